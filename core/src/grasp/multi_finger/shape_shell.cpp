#include "hapticgrasp/grasp/multi_finger/shape_shell.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>

#include "hapticgrasp/math/rpy.hpp"

namespace hg::grasp::multi_finger {
namespace {

Mat3 cross(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace

ShellBalance balanceShell(std::span<const Vec3> fingers, std::span<const Vec3> proxies, int maxIterations) noexcept {
  ShellBalance out;
  const std::size_t n = fingers.size();
  if (n < 1 || n > 5 || proxies.size() != n) return out;
  std::array<Vec3, 5> r;
  Vec3 centre = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    if (!fingers[i].allFinite() || !proxies[i].allFinite()) return out;
    r[i] = proxies[i];
    centre += proxies[i];
  }
  centre /= static_cast<double>(n);
  out.centre = centre;
  out.valid = true;
  double lever2 = 0;
  for (std::size_t i = 0; i < n; ++i) lever2 += (r[i] - centre).squaredNorm();
  const double L = std::max(1e-4, std::sqrt(lever2 / static_cast<double>(n)));

  Mat3 totalR = Mat3::Identity();
  Vec3 totalT = Vec3::Zero();
  for (int it = 0; it < std::max(1, maxIterations); ++it) {
    // Eqs 15/16 linearised about the current r_i (relative to the centre), unknowns
    // z = (Δt, L Δθ): force rows Σe − n Δt + [Σρ]× Δθ, torque rows Σ ρ×e + Σ([ρ]×² +
    // [e]×[ρ]×) Δθ − Σ([ρ]× + [e]×) Δt, with ρ_i = r_i − c and e_i = p_i − r_i.
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    Vec3 sumRho = Vec3::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 rho = r[i] - centre, e = fingers[i] - r[i];
      const Mat3 R = cross(rho), E = cross(e);
      sumRho += rho;
      b.head<3>() -= e;
      b.tail<3>() -= rho.cross(e) / L;
      A.block<3, 3>(3, 0) -= (R + E) / L;
      A.block<3, 3>(3, 3) += (R * R + E * R) / (L * L);
    }
    A.block<3, 3>(0, 0) = -static_cast<double>(n) * Mat3::Identity();
    A.block<3, 3>(0, 3) = cross(sumRho) / L;
    const double force = b.head<3>().norm(), torque = b.tail<3>().norm() * L;
    out.residualForce = force;
    out.residualTorque = torque;
    if (force < 1e-12 && torque < 1e-12 * L) break;
    // Minimum-norm least squares, regularised: (AᵀA + εI) z = Aᵀ b.
    Eigen::Matrix<double, 6, 6> M = A.transpose() * A;
    const double eps = 1e-10 * std::max(1.0, M.trace() / 6.0);
    M.diagonal().array() += eps;
    const Eigen::Matrix<double, 6, 1> z = M.ldlt().solve(A.transpose() * b);
    if (!z.allFinite()) break;
    const Vec3 dt = z.head<3>();
    Vec3 dtheta = z.tail<3>() / L;
    const double angle = dtheta.norm();
    if (angle > 0.5) dtheta *= 0.5 / angle;  // large imbalance: several passes
    const Mat3 Rd = math::fromRotationVector(dtheta);
    for (std::size_t i = 0; i < n; ++i) r[i] = centre + Rd * (r[i] - centre) + dt;
    totalR = Rd * totalR;
    totalT = Rd * totalT + dt;  // composition about the fixed centre
    ++out.iterations;
    // Residual after this pass.
    Vec3 f = Vec3::Zero(), t = Vec3::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      f += fingers[i] - r[i];
      t += (r[i] - out.centre).cross(fingers[i] - r[i]);
    }
    out.residualForce = f.norm();
    out.residualTorque = t.norm();
  }
  out.rotation = totalR;
  out.translation = totalT;
  return out;
}

}  // namespace hg::grasp::multi_finger
