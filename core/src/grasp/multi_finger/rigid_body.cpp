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

void RigidBody::correct(const PartPose& pose, double dt) noexcept {
  if (!(dt > 0) || !std::isfinite(dt) || !pose.position.allFinite() || !pose.rotation.allFinite()) return;
  const Vec3 x = pose_.pointToAbsolute(centre_);
  const Vec3 turn = math::rotationVector(pose.rotation * pose_.rotation.transpose());
  v_ += (pose.pointToAbsolute(centre_) - x) / dt;
  w_ += turn / dt;
  pose_ = pose;
}

void RigidBody::stepCoupled(std::span<const Vec3> rho, std::span<const Vec3> f0, std::span<const double> g,
                            std::span<Vec3> applied, const Vec3& force, const Vec3& torque, double dt) noexcept {
  const std::size_t n = rho.size();
  if (!(dt > 0) || !std::isfinite(dt) || f0.size() != n || g.size() != n || applied.size() < n ||
      !force.allFinite() || !torque.allFinite())
    return;
  // (M + dt D) u' = M u + dt F0, u = (v, ω); contact j: J_j u = v − [rho_j]× ω, D = Σ g_j J_jᵀ J_j,
  // F0 = Σ J_jᵀ f0_j + (force, torque), J_jᵀ = (I; [rho_j]×).
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  const Mat3 Iw = pose_.rotation * inertia_ * pose_.rotation.transpose();
  Mat6 A = Mat6::Zero();
  A.topLeftCorner<3, 3>() = m_ * Mat3::Identity();
  A.bottomRightCorner<3, 3>() = Iw;
  Vec6 b;
  b.head<3>() = m_ * v_ + dt * force;
  b.tail<3>() = Iw * w_ + dt * torque;
  for (std::size_t j = 0; j < n; ++j) {
    if (!rho[j].allFinite() || !f0[j].allFinite() || !(g[j] >= 0) || !std::isfinite(g[j])) return;
    Mat3 S;  // [rho]×
    S << 0, -rho[j].z(), rho[j].y(), rho[j].z(), 0, -rho[j].x(), -rho[j].y(), rho[j].x(), 0;
    const double h = dt * g[j];
    A.topLeftCorner<3, 3>().diagonal().array() += h;
    A.topRightCorner<3, 3>() -= h * S;                    // J = (I, −S): JᵀJ = (I, −S; S, −S²)
    A.bottomLeftCorner<3, 3>() += h * S;
    A.bottomRightCorner<3, 3>() -= h * S * S;
    b.head<3>() += dt * f0[j];
    b.tail<3>() += dt * rho[j].cross(f0[j]);
  }
  const Vec6 u = A.ldlt().solve(b);
  if (!u.allFinite()) return;
  const Vec3 x = pose_.pointToAbsolute(centre_);
  v_ = u.head<3>();
  w_ = u.tail<3>();
  for (std::size_t j = 0; j < n; ++j) applied[j] = f0[j] - g[j] * (v_ + w_.cross(rho[j]));
  const Vec3 xNew = x + dt * v_;
  pose_.rotation = math::orthonormalized(math::fromRotationVector(dt * w_) * pose_.rotation);
  pose_.position = xNew - pose_.rotation * centre_;
  springForce_ = springTorque_ = Vec3::Zero();
  for (std::size_t j = 0; j < n; ++j) {
    springForce_ += applied[j];
    springTorque_ += rho[j].cross(applied[j]);
  }
}

}  // namespace hg::grasp::multi_finger
