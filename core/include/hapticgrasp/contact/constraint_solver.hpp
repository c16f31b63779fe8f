#pragma once
// Where the carried part goes this sub-step: the displacement Δq = (Δt, Δθ) (translation of
// its centre c and rotation vector about c, world) closest to the one the hand asks for,
// Δq*, in the virtual coupling's own energy metric K = diag(k_t I, k_r I), such that no
// contact closes past zero gap and every contact's tangential force stays within Coulomb's
// cone:
//
//   minimise ½ (Δq − Δq*)ᵀ K (Δq − Δq*)
//   subject to  a_jᵀ Δq ≥ −g_j,  a_j = [n_j; r_j × n_j],  r_j = p_j − c   (non-penetration)
//               |λ_t,j| ≤ μ λ_n,j on the rows [t; r_j × t] of two tangents (friction)
//
// Because the metric is the coupling's stiffness, the multipliers λ are the contact forces
// in newtons and K (Δq − Δq*) = Σ a_j λ_j is the coupling's pull balanced by the contacts:
// the quasi-static god object of Ortega, Redon & Coquillart, in 6 DOF. Solved by projected
// Gauss-Seidel on the dual (λ_n ≥ 0, λ_t clamped to the cone of the current λ_n), which
// handles hundreds of redundant rows (a peg's whole side in its hole) in fixed work. Each
// contact's forces start from what they were at the previous solve (warm start, by the
// contact's key): Gauss-Seidel's progress then accumulates over ticks, and a part at rest
// among many redundant contacts does not creep along the residual of a cold start.
// Preallocated; solve() allocates nothing and never throws.
#include <cstdint>
#include <span>
#include <vector>

#include "hapticgrasp/contact/contact_query.hpp"

namespace hg::contact {

using Vec6 = Eigen::Matrix<double, 6, 1>;

struct CouplingStiffness {
  double translational_N_m = 2000;
  double rotational_Nm_rad = 5;
};

struct ConstraintSolution {
  Vec6 displacement = Vec6::Zero();  // Δq
  Vec3 force_N = Vec3::Zero();       // Σ λ_j n_j (+ friction): what the contacts do to the part
  Vec3 torque_Nm = Vec3::Zero();     // about c
  double normalForce_N = 0;          // Σ λ_n
  int active = 0;                    // contacts with λ_n > 0
};

class ConstraintSolver {
 public:
  // maxKeys: contact keys lie in [0, maxKeys) (ContactQuery::keyCount()); others start cold.
  explicit ConstraintSolver(int maxContacts = 512, int maxKeys = 0);

  const ConstraintSolution& solve(const Vec6& target, std::span<const Contact> contacts, const Vec3& centre,
                                  const CouplingStiffness& stiffness, double friction, int iterations) noexcept;

 private:
  struct Row {
    Vec6 a = Vec6::Zero();   // the row (n or t, and r × it)
    Vec6 ka = Vec6::Zero();  // K⁻¹ a
    double inverseMass = 0;  // 1 / (aᵀ K⁻¹ a)
    double bias = 0;         // −g for a normal row, 0 for a tangent
    double lambda = 0;
  };
  std::vector<Row> rows_;  // three per contact: normal, tangent 1, tangent 2
  ConstraintSolution solution_;
  struct Warm {
    double lambda[3] = {0, 0, 0};
    std::uint64_t solve = 0;  // the solve that wrote it
  };
  std::vector<Warm> warm_;  // by contact key
  std::uint64_t solves_ = 0;
};

}  // namespace hg::contact
