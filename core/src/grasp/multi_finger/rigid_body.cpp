#include "hapticgrasp/grasp/multi_finger/rigid_body.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "hapticgrasp/math/rpy.hpp"

namespace hg::grasp::multi_finger {

RigidBody::RigidBody(double mass, const Vec3& centre, const Mat3& inertia) noexcept
    : m_(mass > 0 && std::isfinite(mass) ? mass : 1.0),
      centre_(centre.allFinite() ? centre : Vec3::Zero()),
      inertia_(inertia.allFinite() ? Mat3(0.5 * (inertia + inertia.transpose())) : Mat3::Identity()) {
  // A degenerate inertia (a flat or point part): at least a small isotropic part.
  const double floor = 1e-9 * std::max(1e-12, inertia_.trace());
  inertia_.diagonal().array() += floor + 1e-15;
}

void RigidBody::reset(const PartPose& pose) noexcept {
  pose_ = pose;
  v_ = w_ = springForce_ = springTorque_ = Vec3::Zero();
}

void RigidBody::step(const PartPose& target, const Vec3& targetVelocity, const Vec3& targetAngularVelocity,
                     const SpringDamper6& s, const Vec3& force, const Vec3& torque, double dt) noexcept {
  if (!(dt > 0) || !std::isfinite(dt) || !target.position.allFinite() || !target.rotation.allFinite() ||
      !force.allFinite() || !torque.allFinite() || !targetVelocity.allFinite() || !targetAngularVelocity.allFinite())
    return;
  const double k = std::max(0.0, s.k), c = std::max(0.0, s.c), kr = std::max(0.0, s.kr), cr = std::max(0.0, s.cr);
  // Translation of the centre of gravity, backward Euler on the spring-damper.
  const Vec3 x = pose_.pointToAbsolute(centre_);
  const Vec3 xs = target.pointToAbsolute(centre_);
  v_ = (m_ * v_ + dt * (force + k * (xs - x) + c * targetVelocity)) / (m_ + dt * (c + dt * k));
  const Vec3 xNew = x + dt * v_;
  // Rotation: φ = rotation vector of R_s R_bᵀ (world), (I + dt cr + dt² kr) ω' = I ω + dt (τ + kr φ + cr ω_s).
  const Vec3 phi = math::rotationVector(target.rotation * pose_.rotation.transpose());
  const Mat3 Iw = pose_.rotation * inertia_ * pose_.rotation.transpose();
  Mat3 M = Iw;
  M.diagonal().array() += dt * (cr + dt * kr);
  const Vec3 rhs = Iw * w_ + dt * (torque + kr * phi + cr * targetAngularVelocity);
  const Vec3 w = M.ldlt().solve(rhs);
  if (w.allFinite() && xNew.allFinite()) {
    w_ = w;
    pose_.rotation = math::orthonormalized(math::fromRotationVector(dt * w_) * pose_.rotation);
    pose_.position = xNew - pose_.rotation * centre_;
  }
  const Vec3 phiNew = math::rotationVector(target.rotation * pose_.rotation.transpose());
  springForce_ = k * (xs - pose_.pointToAbsolute(centre_)) + c * (targetVelocity - v_);
  springTorque_ = kr * phiNew + cr * (targetAngularVelocity - w_);
}

}  // namespace hg::grasp::multi_finger
