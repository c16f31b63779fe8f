#pragma once
// The scene's broad phase: a bounding-volume hierarchy over the parts' world boxes, so that
// a fingertip costs only the parts whose box holds it, whatever the scene's size.
//
// Built once (median splits along the longest axis of the boxes' centres: a balanced tree,
// depth ⌈log2 n⌉ + 1), then refitted in place when a part moves: its leaf gets the new box
// and every ancestor the union of its two children, O(log n), no allocation. Refitting
// keeps the tree's shape, so a part carried far from where it was built loosens the boxes
// of the branch it sits in; a scene moves one part at a time, which costs little.
//
// Hand-written: OCCT's BVH_Tree needs its builders and sets (allocating) to refit, Embree's
// point queries have no refit of a user geometry without a commit (allocating), and the
// servo thread may neither allocate nor lock.
#include <cstdint>
#include <span>
#include <vector>

#include "hapticgrasp/geometry/aabb.hpp"

namespace hg::grasp {

class BroadPhase {
 public:
  BroadPhase() = default;
  // One box per item (item i is boxes[i]); empty boxes hold nothing.
  explicit BroadPhase(std::span<const geometry::Aabb> boxes);

  std::size_t size() const noexcept { return leafOf_.size(); }
  const geometry::Aabb& box(std::size_t item) const noexcept { return nodes_[leafOf_[item]].box; }

  // Item `item` now has box `box` (servo thread: no allocation).
  void update(std::size_t item, const geometry::Aabb& box) noexcept;

  // The items whose box contains x: the first out.size() of them are written to `out` (in
  // no particular order); returns how many there are, which may exceed out.size().
  std::size_t query(const Vec3& x, std::span<int> out) const noexcept;
  // The items whose box overlaps `box` (a carried part's, inflated by its contact margin),
  // written and counted as query(x) does.
  std::size_t overlapping(const geometry::Aabb& box, std::span<int> out) const noexcept;

 private:
  struct Node {
    geometry::Aabb box;
    int left = -1, right = -1;  // children; -1 for a leaf
    int parent = -1;
    int item = -1;              // a leaf's item
  };
  int build(std::span<int> items, std::span<const geometry::Aabb> boxes, int parent);
  // The leaves under every node whose box `enters` accepts: query's and overlapping's walk.
  template <class Enters>
  std::size_t collect(Enters enters, std::span<int> out) const noexcept;

  std::vector<Node> nodes_;     // nodes_[0] is the root
  std::vector<int> leafOf_;     // item -> its leaf
};

}  // namespace hg::grasp
