#include "hapticgrasp/grasp/force_laws.hpp"

#include <algorithm>
#include <cmath>

#include "hapticgrasp/math/rpy.hpp"

namespace hg::grasp {

Vec3 contactForce(const Vec3& p_a, const Vec3& outward, double depthRate, const GraspParameters& k) noexcept {
  const double depth = p_a.norm();
  const double bracket = std::max(0.0, k.K_c + k.B_c * depthRate);  // clamp: never pull
  const double magnitude = bracket * std::sqrt(depth);
  if (!(magnitude > 0)) return Vec3::Zero();
  // -p/|p| is the outward normal; below ~1e-12 of the part's scale p has no direction.
  const Vec3 direction = depth > 1e-15 ? Vec3(-p_a / depth) : outward;
  return magnitude * direction;
}

double graspingForce(double distance, double distanceRate, double graspDistance, const GraspParameters& k) noexcept {
  const double travel = std::max(0.0, graspDistance + k.d_h - distance);
  const double bracket = std::max(0.0, k.K_g - k.B_g * distanceRate);  // clamp: never pull
  return bracket * std::sqrt(travel);
}

Wrench springWrench(const PartPose& pose, const PartPose& held, const GraspParameters& k) noexcept {
  Wrench w;
  w.force = -k.K_ox * (pose.position - held.position);
  if (k.rotationalSpring == RotationalSpring::RotationVector) {
    // The turn from the held orientation to the current one, as an absolute-frame vector.
    w.moment = -k.K_oe * math::rotationVector(pose.rotation * held.rotation.transpose());
  } else {
    // The paper's form: RPY of R(xi) = rotation^T, differences wrapped so that crossing
    // +/-180 degrees does not flip the moment.
    const Vec3 xi = math::paperRpy(pose.rotation.transpose());
    const Vec3 xiHeld = math::paperRpy(held.rotation.transpose());
    w.moment = -k.K_oe * math::wrapAngles(xi - xiHeld);
  }
  return w;
}

Wrench gravityWrench(const PartPose& pose, const Vec3& x_g_o, double mass, const Vec3& wrist,
                     const GraspParameters& k) noexcept {
  Wrench w;
  w.force = mass * k.gravity;
  w.moment = (pose.pointToAbsolute(x_g_o) - wrist).cross(w.force);
  return w;
}

bool springsCarryWeight(const Vec3& wristForce, double mass, const GraspParameters& k) noexcept {
  return wristForce.dot(k.gravity) >= mass * k.gravity.squaredNorm();
}

}  // namespace hg::grasp
