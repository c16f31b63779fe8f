#pragma once
// A bounding volume hierarchy over the features (faces, edges, vertices) of a part, built
// with OCCT's BVH builder; the traversal is ours: nearest box first, pruned by the best
// distance so far, on a fixed stack so that a query never allocates.
#include <BVH_BinaryTree.hxx>
#include <BVH_Tree.hxx>

#include <vector>

#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/geometry/penetration.hpp"

namespace hg::geometry::exact {

struct FeatureRef {
  Feature kind;
  int index;  // 0-based into the back end's model arrays
};

class FeatureBvh {
 public:
  void add(FeatureRef feature, const Aabb& box);
  void build();

  // Calls visit(feature) for every feature whose box is closer to x than sqrt(bound2()),
  // nearest boxes first. `bound2` is re-read after each visit: it shrinks as the caller
  // finds closer features.
  template <class Visit, class Bound2>
  void nearest(const Vec3& x, Visit&& visit, Bound2&& bound2) const noexcept;

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

  std::vector<FeatureRef> pending_;
  std::vector<Aabb> pendingBoxes_;
  opencascade::handle<BVH_Tree<double, 3>> tree_;
  std::vector<FeatureRef> leaves_;  // in the tree's primitive order
  std::vector<Aabb> leafBoxes_;
};

template <class Visit, class Bound2>
void FeatureBvh::nearest(const Vec3& x, Visit&& visit, Bound2&& bound2) const noexcept {
  if (tree_.IsNull() || tree_->Length() == 0) return;
  struct Entry {
    int node;
    double d2;
  };
  Entry stack[2 * BVH_Constants_MaxTreeDepth + 2];
  int top = 0;
  stack[top++] = {0, squaredDistance(tree_->MinPoint(0), tree_->MaxPoint(0), x)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.d2 > bound2()) continue;
    if (tree_->IsOuter(e.node)) {
      for (int i = tree_->BegPrimitive(e.node); i <= tree_->EndPrimitive(e.node); ++i)
        if (leafBoxes_[i].squaredDistance(x) <= bound2()) visit(leaves_[i]);
      continue;
    }
    const int a = tree_->Child<0>(e.node), b = tree_->Child<1>(e.node);
    const double da = squaredDistance(tree_->MinPoint(a), tree_->MaxPoint(a), x);
    const double db = squaredDistance(tree_->MinPoint(b), tree_->MaxPoint(b), x);
    if (top + 2 > static_cast<int>(std::size(stack))) continue;  // cannot happen: depth is bounded
    if (da <= db) {
      stack[top++] = {b, db};
      stack[top++] = {a, da};
    } else {
      stack[top++] = {a, da};
      stack[top++] = {b, db};
    }
  }
}

}  // namespace hg::geometry::exact
