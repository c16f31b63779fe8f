#pragma once
// The shape shell's balance (the resultant-force paper's section 5.1, eqs 13–18): the
// mass-less copy of the part's shape moves rigidly by a small rotation Δθ and translation
// Δt until the finger springs f'_i = k (p_i − r'_i), r'_i ≈ r_i + Δθ × r_i + Δt (eq 17),
// sum to no force (eq 15) and no torque (eq 16). Linearised in (Δt, Δθ) and solved as a
// 6×6 system, repeated (Newton) with the exact rotation applied between passes so a
// large imbalance still converges. Directions the springs do not constrain (the spin of
// two fingers' shell about the line through them) get no motion: a regularised,
// minimum-norm solve. Fixed-size, allocation-free, never NaN.
#include <span>

#include "hapticgrasp/math/types.hpp"

namespace hg::grasp::multi_finger {

struct ShellBalance {
  Vec3 translation = Vec3::Zero();  // Δt [m]
  Mat3 rotation = Mat3::Identity();  // about `centre`: r' = centre + R (r − centre) + Δt
  Vec3 centre = Vec3::Zero();       // the god objects' centroid [m]
  double residualForce = 0;         // |Σ f'_i| / k after balancing [m]
  double residualTorque = 0;        // |Σ (r'_i − c) × f'_i| / k [m²]
  int iterations = 0;
  bool valid = false;               // 1..5 finite springs
};

// fingers p_i and god objects r_i, world frame, same count (1..5). A single finger pushes
// the shell away along its spring (nothing balances it).
ShellBalance balanceShell(std::span<const Vec3> fingers, std::span<const Vec3> proxies,
                          int maxIterations = 4) noexcept;

}  // namespace hg::grasp::multi_finger
