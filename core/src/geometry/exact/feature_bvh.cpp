#include "feature_bvh.hpp"

#include <BVH_BinnedBuilder.hxx>
#include <BVH_BoxSet.hxx>

namespace hg::geometry::exact {

void FeatureBvh::add(FeatureRef feature, const LeafBound& bound) {
  pending_.push_back(feature);
  pendingBounds_.push_back(bound);
}

void FeatureBvh::build() {
  // BVH_BoxSet reorders its elements into the tree's primitive order as it builds; we
  // carry the index of each pending feature through it.
  opencascade::handle<BVH_Builder<double, 3>> builder = new BVH_BinnedBuilder<double, 3, 32>(4, BVH_Constants_MaxTreeDepth);
  BVH_BoxSet<double, 3, int> set(builder);
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    const Aabb& b = pendingBounds_[i].box;
    set.Add(static_cast<int>(i), BVH_Box<double, 3>(BVH_Vec3d(b.min.x(), b.min.y(), b.min.z()),
                                                     BVH_Vec3d(b.max.x(), b.max.y(), b.max.z())));
  }
  set.Build();
  tree_ = set.BVH();
  leaves_.clear();
  leafBounds_.clear();
  for (int i = 0; i < set.Size(); ++i) {
    leaves_.push_back(pending_[set.Element(i)]);
    leafBounds_.push_back(pendingBounds_[set.Element(i)]);
  }
  pending_.clear();
  pendingBounds_.clear();
  pending_.shrink_to_fit();
  pendingBounds_.shrink_to_fit();
}

std::size_t FeatureBvh::memoryBytes() const noexcept {
  const std::size_t nodes = tree_.IsNull() ? 0 : static_cast<std::size_t>(tree_->Length());
  return nodes * (2 * sizeof(BVH_Vec3d) + 4 * sizeof(int)) + leaves_.capacity() * sizeof(FeatureRef) +
         leafBounds_.capacity() * sizeof(LeafBound);
}

}  // namespace hg::geometry::exact
