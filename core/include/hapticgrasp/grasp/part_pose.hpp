#pragma once
// Where a part is: the object frame o^o-x^o y^o z^o of the first paper in the absolute
// frame. Kept as a rotation matrix (object -> absolute, the transpose of the paper's
// R(xi_o^a)) and the position x_o^a of the object frame's origin, in metres.
#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/math/types.hpp"

namespace hg::grasp {

struct PartPose {
  Mat3 rotation = Mat3::Identity();  // object -> absolute = R(xi_o^a)^T
  Vec3 position = Vec3::Zero();      // x_o^a

  // Eqs 2-3: a point in the object frame, x^o = R (x^a - x_o^a).
  Vec3 toObject(const Vec3& x_a) const { return rotation.transpose() * (x_a - position); }
  // Eqs 6-7: a vector back to the absolute frame, p^a = R^-1 p^o.
  Vec3 vectorToAbsolute(const Vec3& v_o) const { return rotation * v_o; }
  Vec3 pointToAbsolute(const Vec3& x_o) const { return position + rotation * x_o; }

  // The absolute box around a box given in the object frame (conservative when rotated).
  geometry::Aabb absoluteBounds(const geometry::Aabb& local) const {
    if (local.empty()) return local;
    const Vec3 centre = pointToAbsolute(local.centre());
    const Vec3 half = rotation.cwiseAbs() * (0.5 * local.size());
    return {centre - half, centre + half};
  }
};

}  // namespace hg::grasp
