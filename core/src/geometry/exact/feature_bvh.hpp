#pragma once
// A bounding volume hierarchy over the features (faces or pieces of faces, edges or pieces
// of edges, vertices) of a part, built with OCCT's BVH builder; the traversal is ours:
// nearest bound first, pruned by the best distance so far, with fixed-size storage so
// that a query never allocates.
#include <BVH_BinaryTree.hxx>
#include <BVH_Tree.hxx>

#include <algorithm>
#include <vector>

#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/geometry/penetration.hpp"
#include "leaf_bound.hpp"

namespace hg::geometry::exact {

struct FeatureRef {
  Feature kind = Feature::None;
  int index = -1;  // 0-based into the back end's model arrays
  int piece = -1;  // a face's patch or an edge's piece; -1: the whole feature
};

class FeatureBvh {
 public:
  void add(FeatureRef feature, const LeafBound& bound);
  void add(FeatureRef feature, const Aabb& box) { add(feature, LeafBound{box}); }
  void build();

  // Calls visit(feature, squaredLowerBound) for every feature whose bound is closer to x
  // than sqrt(bound2()), nearest bound first. `bound2` is re-read after each visit: it
  // shrinks as the caller finds closer features.
  template <class Visit, class Bound2>
  void nearest(const Vec3& x, Visit&& visit, Bound2&& bound2) const noexcept;

  std::size_t size() const noexcept { return leaves_.size(); }
  const LeafBound& bound(std::size_t leaf) const noexcept { return leafBounds_[leaf]; }
  std::size_t memoryBytes() const noexcept;

 private:
  static double squaredDistance(const BVH_Vec3d& lo, const BVH_Vec3d& hi, const Vec3& x) noexcept {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max({lo[k] - x[k], x[k] - hi[k], 0.0});
      d2 += d * d;
    }
    return d2;
  }

  template <class Visit, class Bound2>
  void nearestFrom(int node, const Vec3& x, Visit& visit, Bound2& bound2) const noexcept;

  std::vector<FeatureRef> pending_;
  std::vector<LeafBound> pendingBounds_;
  opencascade::handle<BVH_Tree<double, 3>> tree_;
  std::vector<FeatureRef> leaves_;  // in the tree's primitive order
  std::vector<LeafBound> leafBounds_;
};

// Best first: a heap of tree nodes and leaves ordered by their lower bound, so that the
// leaf most likely to hold the closest point is searched first and its distance prunes
// the rest. The heap lives on the stack; when it is full, a node's leaves are visited at
// once (still correct, only less well ordered).
template <class Visit, class Bound2>
void FeatureBvh::nearest(const Vec3& x, Visit&& visit, Bound2&& bound2) const noexcept {
  if (tree_.IsNull() || tree_->Length() == 0) return;
  struct Entry {
    double d2;
    int node;  // >= 0: a tree node; < 0: leaf -node - 1
  };
  constexpr int kCapacity = 384;
  Entry heap[kCapacity];
  int size = 0;
  auto later = [](const Entry& a, const Entry& b) { return a.d2 > b.d2; };  // min-heap
  auto push = [&](const Entry& e) {
    if (size == kCapacity) return false;
    heap[size++] = e;
    std::push_heap(heap, heap + size, later);
    return true;
  };
  push({squaredDistance(tree_->MinPoint(0), tree_->MaxPoint(0), x), 0});
  while (size > 0) {
    std::pop_heap(heap, heap + size, later);
    const Entry e = heap[--size];
    if (e.d2 > bound2()) break;  // everything left is farther
    if (e.node < 0) {
      visit(leaves_[-e.node - 1], e.d2);
      continue;
    }
    if (tree_->IsOuter(e.node)) {
      for (int i = tree_->BegPrimitive(e.node); i <= tree_->EndPrimitive(e.node); ++i) {
        const double d2 = leafBounds_[i].squaredDistance(x);
        if (d2 <= bound2() && !push({d2, -i - 1})) visit(leaves_[i], d2);
      }
      continue;
    }
    for (const int child : {tree_->Child<0>(e.node), tree_->Child<1>(e.node)}) {
      const double d2 = squaredDistance(tree_->MinPoint(child), tree_->MaxPoint(child), x);
      if (d2 <= bound2() && !push({d2, child})) {
        // No room: descend this child depth first, as the tree orders it.
        nearestFrom(child, x, visit, bound2);
      }
    }
  }
}

template <class Visit, class Bound2>
void FeatureBvh::nearestFrom(int node, const Vec3& x, Visit& visit, Bound2& bound2) const noexcept {
  if (tree_->IsOuter(node)) {
    for (int i = tree_->BegPrimitive(node); i <= tree_->EndPrimitive(node); ++i) {
      const double d2 = leafBounds_[i].squaredDistance(x);
      if (d2 <= bound2()) visit(leaves_[i], d2);
    }
    return;
  }
  for (const int child : {tree_->Child<0>(node), tree_->Child<1>(node)})
    if (squaredDistance(tree_->MinPoint(child), tree_->MaxPoint(child), x) <= bound2())
      nearestFrom(child, x, visit, bound2);
}

}  // namespace hg::geometry::exact
