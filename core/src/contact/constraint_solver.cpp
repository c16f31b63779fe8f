#include "hapticgrasp/contact/constraint_solver.hpp"

#include <algorithm>
#include <cmath>

namespace hg::contact {
namespace {

// Two unit tangents completing n to an orthonormal frame.
void tangents(const Vec3& n, Vec3& t1, Vec3& t2) noexcept {
  t1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  t2 = n.cross(t1);
}

}  // namespace

ConstraintSolver::ConstraintSolver(int maxContacts, int maxKeys)
    : rows_(3 * static_cast<std::size_t>(std::max(maxContacts, 1))),
      warm_(static_cast<std::size_t>(std::max(maxKeys, 0))) {}

const ConstraintSolution& ConstraintSolver::solve(const Vec6& target, std::span<const Contact> contacts,
                                                  const Vec3& centre, const CouplingStiffness& stiffness,
                                                  double friction, int iterations) noexcept {
  const std::size_t m = std::min(contacts.size(), rows_.size() / 3);
  Vec6 kInverse;
  kInverse << Vec3::Constant(1 / stiffness.translational_N_m), Vec3::Constant(1 / stiffness.rotational_Nm_rad);
  const auto setRow = [&](Row& row, const Vec3& direction, const Vec3& r, double bias) {
    row.a << direction, r.cross(direction);
    row.ka = kInverse.cwiseProduct(row.a);
    row.inverseMass = 1 / std::max(row.a.dot(row.ka), 1e-300);
    row.bias = bias;
    row.lambda = 0;
  };
  for (std::size_t j = 0; j < m; ++j) {
    const Contact& c = contacts[j];
    const Vec3 r = c.point - centre;
    Vec3 t1, t2;
    tangents(c.normal, t1, t2);
    setRow(rows_[3 * j], c.normal, r, -c.gap);
    setRow(rows_[3 * j + 1], t1, r, 0);
    setRow(rows_[3 * j + 2], t2, r, 0);
  }
  // Warm start: the forces of the contacts that were there at the previous solve.
  Vec6 dq = target;
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t key = static_cast<std::size_t>(contacts[j].key);
    if (key >= warm_.size() || warm_[key].solve != solves_ || solves_ == 0) continue;
    const double lambdaN = std::max(0.0, warm_[key].lambda[0]);
    for (int k = 0; k < 3; ++k) {
      Row& row = rows_[3 * j + k];
      row.lambda = k == 0 ? lambdaN : std::clamp(warm_[key].lambda[k], -friction * lambdaN, friction * lambdaN);
      dq += row.ka * row.lambda;
    }
  }
  // Projected Gauss-Seidel: Δq = Δq* + Σ K⁻¹ a λ, each row's λ moved to satisfy its row,
  // then projected (λ_n ≥ 0; |λ_t| ≤ μ λ_n).
  for (int it = 0; it < iterations; ++it) {
    double change = 0;
    for (std::size_t j = 0; j < m; ++j) {
      Row& normal = rows_[3 * j];
      const double lambdaN = std::max(0.0, normal.lambda - (normal.a.dot(dq) - normal.bias) * normal.inverseMass);
      dq += normal.ka * (lambdaN - normal.lambda);
      change = std::max(change, std::abs(lambdaN - normal.lambda));
      normal.lambda = lambdaN;
      const double limit = friction * lambdaN;
      for (int k = 1; k <= 2; ++k) {
        Row& tangent = rows_[3 * j + k];
        if (limit == 0 && tangent.lambda == 0) continue;
        const double lambdaT = std::clamp(tangent.lambda - tangent.a.dot(dq) * tangent.inverseMass, -limit, limit);
        dq += tangent.ka * (lambdaT - tangent.lambda);
        change = std::max(change, std::abs(lambdaT - tangent.lambda));
        tangent.lambda = lambdaT;
      }
    }
    if (change < 1e-5) break;  // N: a hundredth of a gram's weight
  }
  ++solves_;
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t key = static_cast<std::size_t>(contacts[j].key);
    if (key >= warm_.size()) continue;
    warm_[key].solve = solves_;
    for (int k = 0; k < 3; ++k) warm_[key].lambda[k] = rows_[3 * j + k].lambda;
  }
  ConstraintSolution& s = solution_;
  s = {};
  s.displacement = dq;
  for (std::size_t j = 0; j < m * 3; ++j) {
    s.force_N += rows_[j].a.head<3>() * rows_[j].lambda;
    s.torque_Nm += rows_[j].a.tail<3>() * rows_[j].lambda;
  }
  for (std::size_t j = 0; j < m; ++j) {
    s.normalForce_N += rows_[3 * j].lambda;
    if (rows_[3 * j].lambda > 0) ++s.active;
  }
  return s;
}

}  // namespace hg::contact
