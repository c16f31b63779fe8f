#include "hapticgrasp/math/rpy.hpp"

#include <cmath>
#include <numbers>

namespace hg::math {

Mat3 paperRotation(const Vec3& rpy) noexcept {
  const double cx = std::cos(rpy.x()), cy = std::cos(rpy.y()), cz = std::cos(rpy.z());
  const double sx = std::sin(rpy.x()), sy = std::sin(rpy.y()), sz = std::sin(rpy.z());
  Mat3 R;
  // Eq 1, row by row as printed.
  R << cy * cz, cx * sz + sx * sy * cz, sx * sz - cx * sy * cz,
      -cy * sz, cx * cz - sx * sy * sz, sx * cz + cx * sy * sz,
      sy, -sx * cy, cx * cy;
  return R;
}

Vec3 paperRpy(const Mat3& R) noexcept {
  // Eq 1's first column is cos(pitch) * (cos yaw, -sin yaw, *): yaw from it, pitch from its
  // third row against the column's length (never negative, so pitch stays in [-90, 90]).
  const double yaw = std::atan2(-R(1, 0), R(0, 0));
  const double pitch = std::atan2(R(2, 0), std::hypot(R(0, 0), R(1, 0)));
  // With yaw removed, R^T Rz(yaw)^T = Rx(roll) Ry(pitch), whose middle column is
  // (0, cos roll, sin roll) whatever the pitch: roll from it is well conditioned even in
  // gimbal lock, where yaw = atan2(0, 0) = 0 and roll absorbs the whole turn.
  const double cz = std::cos(yaw), sz = std::sin(yaw);
  const double sinRoll = R(0, 2) * sz + R(1, 2) * cz;
  const double cosRoll = R(0, 1) * sz + R(1, 1) * cz;
  return {std::atan2(sinRoll, cosRoll), pitch, yaw};
}

Vec3 paperRpyAsPrinted(const Mat3& R) noexcept {
  const double yaw = std::atan2(-R(1, 0), R(0, 0));
  return {std::atan2(-R(2, 1), R(2, 2)), std::atan2(R(2, 0), R(0, 0) / std::cos(yaw)), yaw};
}

double wrapAngle(double a) noexcept {
  constexpr double kPi = std::numbers::pi;
  a = std::remainder(a, 2 * kPi);  // [-pi, pi]
  return a <= -kPi ? a + 2 * kPi : a;
}

Vec3 wrapAngles(const Vec3& a) noexcept { return {wrapAngle(a.x()), wrapAngle(a.y()), wrapAngle(a.z())}; }

Vec3 rotationVector(const Mat3& rotation) noexcept {
  Quat q(rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // the short way round: angle in [0, pi]
  const double s = q.vec().norm();
  if (s < 1e-300) return Vec3::Zero();
  // angle = 2 atan2(s, w) is accurate for small and for near-pi angles alike.
  return (2 * std::atan2(s, q.w()) / s) * q.vec();
}

Mat3 fromRotationVector(const Vec3& v) noexcept {
  const double angle = v.norm();
  if (angle < 1e-300) return Mat3::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

Mat3 orthonormalized(const Mat3& m) noexcept { return Quat(m).normalized().toRotationMatrix(); }

}  // namespace hg::math
