#pragma once
// Distribution of a resultant force and torque over the grasping fingers: the
// resultant-force paper's eq 19 (6 DOF, n fingers) and eqs 10/11 (1 DOF, two fingers).
//
// Eq 19, with the erratum of DESIGN.md (the torque term is Σ r_i × k_i n_i):
//
//   P(k_1..k_n, k) = |F − Σ k_i n_i|² + γ1 |N − Σ r_i × k_i n_i|²
//                    + γ2 Σ (k_i − k |f_gi|)² + γ3 (Σ k_i² + k²),     k_i ≥ 0, k ≥ 0.
//
// r_i is the god object of finger i relative to the reference point about which N is
// given, n_i the unit surface normal pointing INTO the part (the direction the finger
// pushes), |f_gi| the finger's grasping-force magnitude. Finger i receives k_i n_i on top
// of its grasping force; k_i ≥ 0 means it only ever pushes harder (requirement 1).
//
// P = ‖A z − b‖² with z = (k_1..k_n, k): 3 force rows, 3 torque rows (×√γ1), n
// proportionality rows (×√γ2) and n+1 regularisation rows (×√γ3). It is solved exactly
// as a non-negative least-squares problem by Lawson–Hanson's active-set method on the
// (diagonally scaled) normal equations, with fixed-size storage: solve() never allocates,
// never throws, and never returns NaN. With γ3 > 0 the normal matrix is positive definite,
// so the minimiser is unique and Lipschitz-continuous in (F, N, r_i, n_i, |f_gi|): a
// continuously changing resultant gives continuously changing k_i (requirement 3). The
// warm start from the last tick's active set only saves iterations.
//
// Choosing γ2. The proportionality term pulls (k_i) towards a multiple of (|f_gi|), and a
// balanced grasp's forces proportional to (|f_gi|) sum to ~no resultant (the paper's eq
// 15): γ2 directly trades the resultant away. Two opposed fingers pushed along their line
// keep only 1 − γ2/(2 + γ2) of the resultant: a third is lost with γ2 = 1. The default
// γ2 = 1e-3 keeps the resultant to ~0.1 % while still choosing the proportional
// distribution wherever the resultant leaves freedom (degenerate grasps); the eqs 10/11
// limit (all of the resultant to one finger) is recovered for two fingers on a line.
#include <array>
#include <cstdint>
#include <span>

#include "hapticgrasp/math/types.hpp"

namespace hg::grasp {

inline constexpr int kMaxDistributionFingers = 5;

// One finger's contact, world frame, SI.
struct FingerContact {
  Vec3 position = Vec3::Zero();  // god-object position r_i [m]
  Vec3 normal = Vec3::Zero();    // surface normal INTO the part (pushing direction); normalised here
  double graspForce = 0;         // |f_gi| [N]; the magnitude is used (negative values: |·|)
};

struct DistributionParams {
  // γ1 [1/m²], the torque weight. ≤ 0 (default) selects 1/L², L the RMS distance of the
  // fingers from the reference point (at least minLeverArm), so that a torque N and a
  // force N/L weigh the same whatever the grasp's size.
  double gamma1 = 0;
  double minLeverArm = 1e-4;  // [m]
  // γ2 [-], proportionality to the grasping forces (see "Choosing γ2" above).
  double gamma2 = 1e-3;
  // γ3 [-], regularisation: smallest total force among equally good ones, and a positive
  // definite problem. Clamped to at least 1e-12.
  double gamma3 = 1e-6;
  // Lawson–Hanson passive-set solves before the fallback (exhaustive enumeration of the
  // at most 2^6 − 1 passive sets: exact, ~1–3 µs). Measured: ~1 warm along a trajectory;
  // mean 2.4, max 12 over 400k random problems cold or from a random warm start.
  int maxIterations = 24;
  // The resultant counts as matched when |residual force| and |residual torque| / L are
  // both below matchTolerance · (|F| + |N| / L) (+ 1e-12 N).
  double matchTolerance = 1e-2;
};

struct DistributionResult {
  int fingers = 0;                  // n; 0 when the input was rejected (see valid)
  std::array<double, kMaxDistributionFingers> k{};          // k_i ≥ 0 [N]
  double kGrasp = 0;                // k ≥ 0 [-], the proportionality factor
  std::array<Vec3, kMaxDistributionFingers> forces{};       // k_i n_i [N], world frame
  Vec3 residualForce = Vec3::Zero();   // F − Σ k_i n_i [N]
  Vec3 residualTorque = Vec3::Zero();  // N − Σ r_i × k_i n_i [N m], about the reference point
  double cost = 0;                  // P at the solution
  double gamma1 = 0;                // γ1 actually used [1/m²]
  double leverArm = 0;              // L [m]
  bool valid = false;               // n in 1..5 and every input finite
  bool matched = false;             // the resultant was reproduced (within matchTolerance)
  bool converged = false;           // optimal (active set or fallback); false only if invalid
  bool usedFallback = false;        // the iteration bound was hit and enumeration answered
  int iterations = 0;               // passive-set solves (Cholesky factorisations) used
  std::uint8_t passiveSet = 0;      // bit j set: z_j > 0 (bits 0..n-1 fingers, bit n: k)
};

// Keeps the warm start (last active set) from tick to tick; one per grasp, per thread.
// Plain data: no heap, solve() is real-time safe.
class ResultantDistributor {
 public:
  explicit ResultantDistributor(const DistributionParams& params = {}) noexcept : params_(params) {}

  // F and N are the force and the torque (about `reference`, world frame) that the fingers
  // together should exert on the part. Fingers keep their slot from tick to tick for the
  // warm start to help (a wrong warm start only costs iterations).
  const DistributionResult& solve(std::span<const FingerContact> fingers, const Vec3& force,
                                  const Vec3& torque, const Vec3& reference) noexcept;

  // Cold start: forget the last active set.
  void reset() noexcept { warmFingers_ = 0; warmPassive_ = 0; }
  // Warm start from this passive set (bits as DistributionResult::passiveSet) next time.
  void setWarmStart(int fingers, std::uint8_t passiveSet) noexcept {
    warmFingers_ = fingers;
    warmPassive_ = passiveSet;
  }

  const DistributionParams& params() const noexcept { return params_; }
  void setParams(const DistributionParams& params) noexcept { params_ = params; }
  const DistributionResult& result() const noexcept { return result_; }

 private:
  DistributionParams params_;
  DistributionResult result_;
  int warmFingers_ = 0;
  std::uint8_t warmPassive_ = 0;
};

// One-shot form (cold start).
DistributionResult distributeResultant(std::span<const FingerContact> fingers, const Vec3& force,
                                       const Vec3& torque, const Vec3& reference,
                                       const DistributionParams& params = {}) noexcept;

// Eqs 10/11, two fingers on a line, with the erratum (the condition is on k_d d_d + f_e).
// Signed components along the line. The grasping springs give the fingers f_gj = −k_g d_j;
// finger 1 is the one the part pushes towards +x (d_1 ≤ 0, f_g1 ≥ 0), finger 2 towards −x
// (d_2 ≥ 0, f_g2 ≤ 0). The resultant R = k_d d_d + f_e is added, as −R, to exactly one finger,
// the one whose grasping force it increases: finger 1 when R ≤ 0, finger 2 when R > 0.
// The fingers' forces on the part then change by R in total, the other finger keeps its
// grasping force, and the gap x_2 − x_1 = l − 2 f_g / k_g (eq 12) does not depend on R.
struct LineDistribution {
  double f1 = 0;  // force on finger 1 [N]
  double f2 = 0;  // force on finger 2 [N]
  bool toFinger1 = true;  // which finger received the resultant
};
LineDistribution distributeOnLine(double kg, double d1, double d2, double kd, double dd,
                                  double fe) noexcept;

}  // namespace hg::grasp
