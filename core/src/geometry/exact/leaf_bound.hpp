#pragma once
// What bounds a leaf of the part's BVH (a face, a patch of one, an edge, a piece of one, a
// vertex): its axis-aligned box (for the tree) and, for patches and pieces, a tighter box
// in their own frame: for a patch, the third axis is its mean normal (the box is then a
// thin slab over it); for a piece of a curve, the first axis is its chord. The distance to
// either box is a lower bound of the distance to the feature; the oriented one is far
// tighter over a curved or slanted patch, where fewer leaves are then searched.
#include <vector>

#include "hapticgrasp/geometry/aabb.hpp"

namespace hg::geometry::exact {

struct LeafBound {
  Aabb box;
  Vec3 centre = Vec3::Zero();
  Mat3 axes = Mat3::Identity();     // columns: the oriented box's unit axes
  Vec3 half = Vec3::Constant(-1);   // its half extents; negative: no oriented box

  bool oriented() const noexcept { return half.x() >= 0; }
  double squaredDistance(const Vec3& x) const noexcept {
    const double d2 = box.squaredDistance(x);
    if (!oriented()) return d2;
    const Vec3 local = axes.transpose() * (x - centre);
    const Vec3 out = (local.cwiseAbs() - half).cwiseMax(0.0);
    return std::max(d2, out.squaredNorm());
  }
  // Where x lies along the third axis (a patch's normal): > 0 above the box, < 0 below,
  // 0 within its thickness (or without an oriented box).
  int side(const Vec3& x) const noexcept {
    if (!oriented()) return 0;
    const double h = axes.col(2).dot(x - centre);
    return h > half.z() ? 1 : h < -half.z() ? -1 : 0;
  }

  // The bound of `points` grown by `margin`: the oriented box has `axis` as its third
  // axis (`axisIsNormal`) or its first, the others along the points' spread across it.
  static LeafBound around(const std::vector<Vec3>& points, const Vec3& axis, bool axisIsNormal, double margin);
};

}  // namespace hg::geometry::exact
