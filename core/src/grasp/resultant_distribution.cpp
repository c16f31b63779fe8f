// Eq 19 of the resultant-force paper as a non-negative least-squares problem, solved
// exactly by Lawson–Hanson's active-set method on fixed-size arrays (no heap, no throw).
#include "hapticgrasp/grasp/resultant_distribution.hpp"

#include <algorithm>
#include <cmath>

namespace hg::grasp {
namespace {

constexpr int kMaxVars = kMaxDistributionFingers + 1;  // k_1..k_n and k

// The NNLS problem in its normal-equation form: minimise ½ zᵀH z − cᵀz over z ≥ 0, H = AᵀA,
// c = Aᵀb. Diagonally scaled to a unit diagonal before solving (z = D z̃ keeps z ≥ 0), so
// that one tolerance fits every variable however different their units (N and 1).
struct Qp {
  int m = 0;
  double H[kMaxVars][kMaxVars] = {};
  double c[kMaxVars] = {};
};

// Unconstrained minimiser on the passive set P (bit j: z_j free, else z_j = 0): Cholesky
// of H_PP. H is positive definite (γ3 > 0); a pivot below the floor (only reachable with
// pathological parameters) is lifted to it rather than dividing by ~0.
void solvePassive(const Qp& qp, unsigned passive, double* s) noexcept {
  constexpr double kPivotFloor = 1e-15;  // relative to the unit diagonal
  int idx[kMaxVars];
  int p = 0;
  for (int j = 0; j < qp.m; ++j) {
    s[j] = 0;
    if (passive >> j & 1u) idx[p++] = j;
  }
  double L[kMaxVars][kMaxVars];
  for (int a = 0; a < p; ++a) {
    for (int b = 0; b <= a; ++b) {
      double sum = qp.H[idx[a]][idx[b]];
      for (int q = 0; q < b; ++q) sum -= L[a][q] * L[b][q];
      if (a == b) {
        L[a][a] = std::sqrt(sum > kPivotFloor ? sum : kPivotFloor);
      } else {
        L[a][b] = sum / L[b][b];
      }
    }
  }
  double y[kMaxVars];
  for (int a = 0; a < p; ++a) {
    double sum = qp.c[idx[a]];
    for (int q = 0; q < a; ++q) sum -= L[a][q] * y[q];
    y[a] = sum / L[a][a];
  }
  for (int a = p - 1; a >= 0; --a) {
    double sum = y[a];
    for (int q = a + 1; q < p; ++q) sum -= L[q][a] * s[idx[q]];
    s[idx[a]] = sum / L[a][a];
  }
}

struct NnlsOutcome {
  unsigned passive = 0;
  int iterations = 0;
  bool fallback = false;
};

// Exhaustive fallback: every passive set whose unconstrained minimiser is strictly
// positive is a feasible point, and the optimum's own passive set is among them, so the
// lowest objective wins. ≤ 63 Cholesky solves of ≤ 6×6 (a few µs); exact, no iteration.
NnlsOutcome enumerate(const Qp& qp, double* z, int iterations) noexcept {
  NnlsOutcome out;
  out.fallback = true;
  const unsigned full = (1u << qp.m) - 1;
  double best = 0;  // z = 0
  for (int j = 0; j < qp.m; ++j) z[j] = 0;
  double s[kMaxVars];
  for (unsigned mask = 1; mask <= full; ++mask) {
    solvePassive(qp, mask, s);
    ++iterations;
    bool feasible = true;
    double f = 0;  // ½ sᵀHs − cᵀs = −½ cᵀs at the minimiser on the passive set
    for (int j = 0; j < qp.m; ++j) {
      if (!(mask >> j & 1u)) continue;
      if (!(s[j] > 0)) {
        feasible = false;
        break;
      }
      f -= 0.5 * qp.c[j] * s[j];
    }
    if (feasible && f < best) {
      best = f;
      out.passive = mask;
      for (int j = 0; j < qp.m; ++j) z[j] = s[j];
    }
  }
  out.iterations = iterations;
  return out;
}

// Lawson & Hanson (1974), ch. 23, on the normal equations, warm-started from a passive set.
// Each outer step frees the variable with the largest positive gradient −∂f/∂z_j; the
// inner loop keeps z feasible by stepping towards the passive-set minimiser until a
// variable hits zero. If `maxIterations` passive-set solves do not suffice (roundoff
// cycling; never observed), the exhaustive enumeration answers instead.
NnlsOutcome solveNnls(const Qp& qp, unsigned warm, int maxIterations, double* z) noexcept {
  const int m = qp.m;
  const unsigned full = (1u << m) - 1;
  double s[kMaxVars];
  for (int j = 0; j < m; ++j) z[j] = 0;
  unsigned passive = warm & full;
  int iterations = 0;

  // Warm start: the last tick's passive set, pruned until its minimiser is positive.
  while (passive) {
    if (iterations >= maxIterations) return enumerate(qp, z, iterations);
    solvePassive(qp, passive, s);
    ++iterations;
    unsigned bad = 0;
    for (int j = 0; j < m; ++j)
      if ((passive >> j & 1u) && !(s[j] > 0)) bad |= 1u << j;
    if (!bad) {
      for (int j = 0; j < m; ++j) z[j] = s[j];
      break;
    }
    passive &= ~bad;
  }

  double cMax = 0;
  for (int j = 0; j < m; ++j) cMax = std::max(cMax, std::abs(qp.c[j]));

  for (;;) {
    // Gradient w = c − H z on the active set; optimal when none is positive.
    double zMax = 0;
    for (int j = 0; j < m; ++j) zMax = std::max(zMax, z[j]);
    const double tol = 1e-12 * (cMax + m * zMax) + 1e-300;
    int t = -1;
    double wMax = tol;
    for (int j = 0; j < m; ++j) {
      if (passive >> j & 1u) continue;
      double w = qp.c[j];
      for (int q = 0; q < m; ++q) w -= qp.H[j][q] * z[q];
      if (w > wMax) {
        wMax = w;
        t = j;
      }
    }
    if (t < 0) return {passive, iterations, false};
    passive |= 1u << t;

    for (bool first = true;; first = false) {
      if (iterations >= maxIterations) return enumerate(qp, z, iterations);
      solvePassive(qp, passive, s);
      ++iterations;
      // In exact arithmetic s_t > 0 here; otherwise w_t was roundoff and z is optimal.
      if (first && !(s[t] > 0)) return {passive & ~(1u << t), iterations, false};
      double alpha = 1;
      int blocking = -1;
      for (int j = 0; j < m; ++j) {
        if (!(passive >> j & 1u) || s[j] > 0) continue;
        const double a = z[j] / (z[j] - s[j]);  // z_j > 0 ≥ s_j: a in [0, 1)
        if (a < alpha) {
          alpha = a;
          blocking = j;
        }
      }
      if (blocking < 0) {
        for (int j = 0; j < m; ++j) z[j] = s[j];
        break;
      }
      for (int j = 0; j < m; ++j) {
        if (!(passive >> j & 1u)) continue;
        z[j] += alpha * (s[j] - z[j]);
        if (j == blocking || !(z[j] > 0)) {
          z[j] = 0;
          passive &= ~(1u << j);
        }
      }
    }
  }
}

bool finite(const Vec3& v) { return v.allFinite(); }

}  // namespace

const DistributionResult& ResultantDistributor::solve(std::span<const FingerContact> fingers,
                                                      const Vec3& force, const Vec3& torque,
                                                      const Vec3& reference) noexcept {
  DistributionResult& r = result_;
  r = DistributionResult{};
  const int n = static_cast<int>(fingers.size());
  if (n < 1 || n > kMaxDistributionFingers) return r;
  if (!finite(force) || !finite(torque) || !finite(reference)) return r;
  for (const FingerContact& f : fingers)
    if (!finite(f.position) || !finite(f.normal) || !std::isfinite(f.graspForce)) return r;

  // Geometry: unit normals (a zero normal cannot push: its column is zero), lever arms
  // about the reference point, their moments.
  Vec3 normal[kMaxDistributionFingers], arm[kMaxDistributionFingers], moment[kMaxDistributionFingers];
  double g[kMaxDistributionFingers];
  double sumArm2 = 0;
  for (int i = 0; i < n; ++i) {
    const double len = fingers[i].normal.norm();
    normal[i] = len > 1e-300 ? Vec3(fingers[i].normal / len) : Vec3::Zero();
    arm[i] = fingers[i].position - reference;
    moment[i] = arm[i].cross(normal[i]);
    g[i] = std::abs(fingers[i].graspForce);
    sumArm2 += arm[i].squaredNorm();
  }
  const double L = std::max(std::sqrt(sumArm2 / n), std::max(params_.minLeverArm, 1e-12));
  const double g1 = params_.gamma1 > 0 ? params_.gamma1 : 1.0 / (L * L);
  const double g2 = std::max(params_.gamma2, 0.0);
  const double g3 = std::max(params_.gamma3, 1e-12);
  r.leverArm = L;
  r.gamma1 = g1;

  // Normal equations of ‖A z − b‖² (A, b as in the header: P = ‖A z − b‖²).
  Qp qp;
  const int m = n + 1;
  const int kk = n;  // index of k
  qp.m = m;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j <= i; ++j) {
      double h = normal[i].dot(normal[j]) + g1 * moment[i].dot(moment[j]);
      if (i == j) h += g2 + g3;
      qp.H[i][j] = qp.H[j][i] = h;
    }
    qp.H[i][kk] = qp.H[kk][i] = -g2 * g[i];
    qp.c[i] = normal[i].dot(force) + g1 * moment[i].dot(torque);
  }
  double hk = g3;
  for (int i = 0; i < n; ++i) hk += g2 * g[i] * g[i];
  qp.H[kk][kk] = hk;
  qp.c[kk] = 0;

  double d[kMaxVars];
  for (int j = 0; j < m; ++j) d[j] = 1.0 / std::sqrt(qp.H[j][j]);  // H_jj ≥ γ3 > 0
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) qp.H[i][j] *= d[i] * d[j];
    qp.H[i][i] = 1;
    qp.c[i] *= d[i];
  }

  const unsigned warm = warmFingers_ == n ? warmPassive_ : 0u;
  double z[kMaxVars];
  const NnlsOutcome out = solveNnls(qp, warm, params_.maxIterations, z);

  for (int j = 0; j < m; ++j) z[j] = std::max(z[j] * d[j], 0.0);
  Vec3 sumF = Vec3::Zero(), sumN = Vec3::Zero();
  double prop = 0, reg = z[kk] * z[kk];
  for (int i = 0; i < n; ++i) {
    r.k[i] = z[i];
    r.forces[i] = z[i] * normal[i];
    sumF += r.forces[i];
    sumN += z[i] * moment[i];
    const double e = z[i] - z[kk] * g[i];
    prop += e * e;
    reg += z[i] * z[i];
  }
  r.kGrasp = z[kk];
  r.residualForce = force - sumF;
  r.residualTorque = torque - sumN;
  r.cost = r.residualForce.squaredNorm() + g1 * r.residualTorque.squaredNorm() + g2 * prop + g3 * reg;
  if (!std::isfinite(r.cost)) {  // overflowing inputs (|F| ~ 1e154...): no NaN out
    r = DistributionResult{};
    return r;
  }
  r.fingers = n;
  r.valid = true;
  r.converged = true;
  r.usedFallback = out.fallback;
  r.iterations = out.iterations;
  r.passiveSet = static_cast<std::uint8_t>(out.passive);
  const double scale = force.norm() + torque.norm() / L;
  const double tolerance = params_.matchTolerance * scale + 1e-12;
  r.matched = r.residualForce.norm() <= tolerance && r.residualTorque.norm() / L <= tolerance;

  warmFingers_ = n;
  warmPassive_ = static_cast<std::uint8_t>(out.passive);
  return r;
}

DistributionResult distributeResultant(std::span<const FingerContact> fingers, const Vec3& force,
                                       const Vec3& torque, const Vec3& reference,
                                       const DistributionParams& params) noexcept {
  ResultantDistributor distributor(params);
  return distributor.solve(fingers, force, torque, reference);
}

LineDistribution distributeOnLine(double kg, double d1, double d2, double kd, double dd,
                                  double fe) noexcept {
  LineDistribution out;
  const double resultant = kd * dd + fe;  // eqs 10/11: "k_d d + f_e" is k_d d_d + f_e
  out.f1 = -kg * d1;
  out.f2 = -kg * d2;
  if (resultant <= 0) {
    out.f1 -= resultant;  // eq 10
    out.toFinger1 = true;
  } else {
    out.f2 -= resultant;  // eq 11
    out.toFinger1 = false;
  }
  return out;
}

}  // namespace hg::grasp
