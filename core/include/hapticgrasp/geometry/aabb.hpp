#pragma once
#include <algorithm>
#include <limits>

#include "hapticgrasp/math/types.hpp"

namespace hg::geometry {

// Axis-aligned box. The first test of every query: a fingertip far from a part's box
// costs a part nothing more.
struct Aabb {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());

  bool empty() const { return (min.array() > max.array()).any(); }
  Vec3 centre() const { return 0.5 * (min + max); }
  Vec3 size() const { return max - min; }
  double diagonal() const { return size().norm(); }
  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  Aabb inflated(double margin) const {
    return {min - Vec3::Constant(margin), max + Vec3::Constant(margin)};
  }
  bool contains(const Vec3& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
  // Squared distance from p to the box (0 inside).
  double squaredDistance(const Vec3& p) const {
    const Vec3 d = (min - p).cwiseMax(p - max).cwiseMax(Vec3::Zero());
    return d.squaredNorm();
  }
};

// Whether `inner` lies within `outer` (an empty inner lies anywhere).
inline bool contains(const Aabb& outer, const Aabb& inner) {
  return inner.empty() || ((inner.min.array() >= outer.min.array()).all() && (inner.max.array() <= outer.max.array()).all());
}

}  // namespace hg::geometry
