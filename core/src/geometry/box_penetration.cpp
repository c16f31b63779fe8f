#include "hapticgrasp/geometry/box_penetration.hpp"

#include <cmath>
#include <cstdio>

#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::geometry {

BoxPenetration::BoxPenetration(const Aabb& box) : box_(box), centre_(box.centre()), half_(0.5 * box.size()) {
  if (box.empty() || !box.min.allFinite() || !box.max.allFinite())
    throw GeometryError("a box back end needs a finite, non-empty box");
}

std::string BoxPenetration::setting() const {
  char text[96];
  const Vec3 s = 1e3 * box_.size();
  std::snprintf(text, sizeof text, "bounding box %.4g x %.4g x %.4g mm", s.x(), s.y(), s.z());
  return text;
}

Penetration BoxPenetration::query(const Vec3& x, QueryState& state) const noexcept {
  Penetration p;
  const Vec3 q = x - centre_;
  const Vec3 gap = q.cwiseAbs() - half_;  // > 0 along the axes x is beyond the box
  if ((gap.array() <= 0).all()) {
    // Inside: the nearest face is the one of the least depth.
    int axis = 0;
    gap.maxCoeff(&axis);
    const double side = q[axis] < 0 ? -1.0 : 1.0;
    p.inside = true;
    p.depth = -gap[axis];
    p.normal = Vec3::Unit(axis) * side;
    p.foot = x;
    p.foot[axis] = centre_[axis] + side * half_[axis];
    p.feature = Feature::Face;
    p.featureIndex = 2 * axis + (side > 0 ? 2 : 1);
  } else {
    p.foot = centre_ + q.cwiseMax(-half_).cwiseMin(half_);
    const Vec3 away = x - p.foot;
    const double d = away.norm();
    p.depth = -d;
    p.normal = away / d;
    const int beyond = static_cast<int>((gap.array() > 0).count());
    p.feature = beyond == 1 ? Feature::Face : beyond == 2 ? Feature::Edge : Feature::Vertex;
    if (beyond == 1) {
      int axis = 0;
      gap.maxCoeff(&axis);
      p.featureIndex = 2 * axis + (q[axis] > 0 ? 2 : 1);
    }
  }
  p.vector = x - p.foot;
  state.feature = p.feature;
  state.index = p.featureIndex;
  return p;
}

bool BoxPenetration::queryFeature(const Vec3& x, Feature feature, int index, double& u, double& v,
                                  Penetration& out) const noexcept {
  if (feature != Feature::Face || index < 1 || index > 6) return false;
  const int axis = (index - 1) / 2;
  const double side = index % 2 == 0 ? 1.0 : -1.0;
  Vec3 foot = x;
  foot[axis] = centre_[axis] + side * half_[axis];
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;  // the face's own axes: x must project into it
  if (std::abs(foot[a] - centre_[a]) > half_[a] || std::abs(foot[b] - centre_[b]) > half_[b]) return false;
  u = foot[a];
  v = foot[b];
  out.foot = foot;
  out.normal = Vec3::Unit(axis) * side;
  out.vector = x - foot;
  out.depth = -side * (x[axis] - foot[axis]);
  out.feature = Feature::Face;
  out.featureIndex = index;
  return true;
}

MassProperties BoxPenetration::massProperties(const MassSpec& spec) const noexcept {
  MassProperties m;
  const Vec3 s = box_.size();
  m.volume_m3 = s.prod();
  m.mass_kg = spec.kind == MassSpec::Kind::Mass ? spec.value : spec.value * m.volume_m3;
  m.centre_m = centre_;
  const Vec3 s2 = s.cwiseProduct(s);
  m.inertia_kgm2 = (m.mass_kg / 12.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y())).asDiagonal();
  return m;
}

}  // namespace hg::geometry
