// Resultant-force distribution (the resultant-force paper's eq 19 with DESIGN.md's erratum,
// and eqs 10/11): the active-set NNLS against brute-force enumeration of every active set
// on random and degenerate problems, KKT conditions, matching of achievable resultants,
// continuity, extreme magnitudes, no allocation in solve(), and the 1-DOF rule.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "alloc_counter.hpp"
#include "hapticgrasp/grasp/resultant_distribution.hpp"

namespace {

using hg::Vec3;
using hg::grasp::DistributionParams;
using hg::grasp::DistributionResult;
using hg::grasp::FingerContact;
using hg::grasp::ResultantDistributor;

struct Problem {
  std::vector<FingerContact> fingers;
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
  Vec3 reference = Vec3::Zero();
  DistributionParams params;
};

// P = ‖A z − b‖², built from eq 19's definition independently of the library.
struct LeastSquares {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  double gamma1 = 0;
  double leverArm = 0;
};

LeastSquares buildLeastSquares(const Problem& p) {
  const int n = static_cast<int>(p.fingers.size());
  double sum = 0;
  for (const auto& f : p.fingers) sum += (f.position - p.reference).squaredNorm();
  LeastSquares ls;
  ls.leverArm = std::max(std::sqrt(sum / n), p.params.minLeverArm);
  ls.gamma1 = p.params.gamma1 > 0 ? p.params.gamma1 : 1 / (ls.leverArm * ls.leverArm);
  const double s1 = std::sqrt(ls.gamma1), s2 = std::sqrt(p.params.gamma2),
               s3 = std::sqrt(std::max(p.params.gamma3, 1e-12));
  ls.A = Eigen::MatrixXd::Zero(6 + n + n + 1, n + 1);
  ls.b = Eigen::VectorXd::Zero(6 + n + n + 1);
  ls.b.head<3>() = p.force;
  ls.b.segment<3>(3) = s1 * p.torque;
  for (int i = 0; i < n; ++i) {
    const Vec3 normal = p.fingers[i].normal.norm() > 0 ? Vec3(p.fingers[i].normal.normalized()) : Vec3::Zero();
    ls.A.block<3, 1>(0, i) = normal;
    ls.A.block<3, 1>(3, i) = s1 * (p.fingers[i].position - p.reference).cross(normal);
    ls.A(6 + i, i) = s2;
    ls.A(6 + i, n) = -s2 * std::abs(p.fingers[i].graspForce);
  }
  for (int j = 0; j <= n; ++j) ls.A(6 + n + j, j) = s3;
  return ls;
}

double costOf(const LeastSquares& ls, const Eigen::VectorXd& z) { return (ls.A * z - ls.b).squaredNorm(); }

Eigen::VectorXd solutionOf(const DistributionResult& r) {
  Eigen::VectorXd z(r.fingers + 1);
  for (int i = 0; i < r.fingers; ++i) z[i] = r.k[i];
  z[r.fingers] = r.kGrasp;
  return z;
}

// Every passive set: the least-squares solution on its columns (QR), kept when it is
// non-negative; the lowest P among those is the NNLS optimum.
struct BruteForce {
  double cost = 0;
  Eigen::VectorXd z;
};
BruteForce bruteForce(const LeastSquares& ls) {
  const int m = static_cast<int>(ls.A.cols());
  BruteForce best{ls.b.squaredNorm(), Eigen::VectorXd::Zero(m)};
  for (unsigned mask = 1; mask < (1u << m); ++mask) {
    std::vector<int> cols;
    for (int j = 0; j < m; ++j)
      if (mask >> j & 1u) cols.push_back(j);
    Eigen::MatrixXd As(ls.A.rows(), cols.size());
    for (std::size_t q = 0; q < cols.size(); ++q) As.col(q) = ls.A.col(cols[q]);
    const Eigen::VectorXd zs = As.colPivHouseholderQr().solve(ls.b);
    if ((zs.array() < 0).any()) continue;
    Eigen::VectorXd z = Eigen::VectorXd::Zero(m);
    for (std::size_t q = 0; q < cols.size(); ++q) z[cols[q]] = zs[q];
    const double c = costOf(ls, z);
    if (c < best.cost) best = {c, z};
  }
  return best;
}

double logUniform(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return std::exp(u(rng));
}
Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Vec3 v;
  do v = Vec3(g(rng), g(rng), g(rng));
  while (v.norm() < 1e-6);
  return v.normalized();
}

// A random grasp of a part of size `size` around the origin: fingers on a sphere with
// normals roughly towards the centre (sometimes arbitrary), random grasping forces
// (sometimes zero), random resultant of magnitude `magnitude`.
Problem randomProblem(std::mt19937_64& rng, int n, double size, double magnitude) {
  std::uniform_real_distribution<double> u(0, 1);
  Problem p;
  p.reference = 0.2 * size * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
  for (int i = 0; i < n; ++i) {
    FingerContact f;
    const Vec3 dir = randomUnit(rng);
    f.position = size * (0.5 + 0.5 * u(rng)) * dir;
    f.normal = u(rng) < 0.8 ? Vec3((-dir + 0.7 * randomUnit(rng)).normalized()) : randomUnit(rng);
    if (u(rng) < 0.3) f.normal *= 3.7;  // not unit: normalised by the library
    f.graspForce = u(rng) < 0.15 ? 0.0 : logUniform(rng, 1e-2, 1e2) * (magnitude > 0 ? 1 : 0);
    p.fingers.push_back(f);
  }
  // Degenerate families: coincident fingers, one face (equal normals), opposed pairs.
  const double family = u(rng);
  if (n >= 2 && family < 0.08) {
    p.fingers[1] = p.fingers[0];
  } else if (n >= 2 && family < 0.16) {
    for (auto& f : p.fingers) f.normal = p.fingers[0].normal;
  } else if (n >= 2 && family < 0.24) {
    p.fingers[1].normal = -p.fingers[0].normal;
    p.fingers[1].position = p.fingers[0].position + size * p.fingers[0].normal.normalized();
  }
  p.force = magnitude * randomUnit(rng) * u(rng);
  p.torque = magnitude * size * randomUnit(rng) * u(rng);
  const double pick = u(rng);
  if (pick < 0.25) p.params.gamma2 = 1.0;
  else if (pick < 0.35) p.params.gamma2 = 30.0;
  else if (pick < 0.45) p.params.gamma2 = 0;
  if (u(rng) < 0.2) p.params.gamma3 = 1e-3;
  if (u(rng) < 0.2) p.params.gamma1 = logUniform(rng, 1e-2, 1e2) / (size * size);
  return p;
}

DistributionResult solve(const Problem& p, ResultantDistributor* distributor = nullptr) {
  if (distributor) {
    distributor->setParams(p.params);
    return distributor->solve(p.fingers, p.force, p.torque, p.reference);
  }
  return hg::grasp::distributeResultant(p.fingers, p.force, p.torque, p.reference, p.params);
}

void expectFiniteAndNonNegative(const DistributionResult& r) {
  for (int i = 0; i < r.fingers; ++i) {
    EXPECT_TRUE(std::isfinite(r.k[i]));
    EXPECT_GE(r.k[i], 0.0);
    EXPECT_TRUE(r.forces[i].allFinite());
  }
  EXPECT_TRUE(std::isfinite(r.kGrasp));
  EXPECT_GE(r.kGrasp, 0.0);
  EXPECT_TRUE(r.residualForce.allFinite());
  EXPECT_TRUE(r.residualTorque.allFinite());
  EXPECT_TRUE(std::isfinite(r.cost));
}

// The active-set optimum against enumeration, to 1e-9 relative in P.
void expectOptimal(const Problem& p, const DistributionResult& r, const char* what) {
  ASSERT_TRUE(r.valid) << what;
  const LeastSquares ls = buildLeastSquares(p);
  EXPECT_NEAR(r.gamma1, ls.gamma1, 1e-12 * ls.gamma1) << what;
  const BruteForce bf = bruteForce(ls);
  const Eigen::VectorXd z = solutionOf(r);
  const double cost = costOf(ls, z);
  const double tol = 1e-9 * bf.cost + 1e-14 * ls.b.squaredNorm() + 1e-300;
  EXPECT_NEAR(cost, bf.cost, tol) << what << " n=" << r.fingers;
  EXPECT_NEAR(r.cost, cost, 1e-9 * cost + 1e-300) << what;
  expectFiniteAndNonNegative(r);
}

TEST(ResultantDistribution, MatchesBruteForceEnumeration) {
  std::mt19937_64 rng(19);
  std::uniform_int_distribution<int> fingers(1, 5);
  std::uniform_int_distribution<unsigned> warm(0, 63);
  ResultantDistributor distributor;
  int fallbacks = 0, worst = 0;
  int activeSizes[3] = {0, 0, 0};  // optimum with 0, 1, ≥ 2 variables at zero
  double sumIterations = 0;
  constexpr int kProblems = 20000;
  for (int trial = 0; trial < kProblems; ++trial) {
    const int n = fingers(rng);
    const Problem p = randomProblem(rng, n, logUniform(rng, 1e-3, 10), logUniform(rng, 1e-6, 1e4));
    const LeastSquares ls = buildLeastSquares(p);
    const BruteForce bf = bruteForce(ls);
    const double tol = 1e-9 * bf.cost + 1e-14 * ls.b.squaredNorm() + 1e-300;
    // Cold, then from a random (mostly wrong) warm start: the same optimum.
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 0) distributor.reset();
      else distributor.setWarmStart(n, static_cast<std::uint8_t>(warm(rng)));
      const DistributionResult r = solve(p, &distributor);
      ASSERT_TRUE(r.valid);
      ASSERT_TRUE(r.converged);
      expectFiniteAndNonNegative(r);
      const double cost = costOf(ls, solutionOf(r));
      ASSERT_NEAR(cost, bf.cost, tol) << "trial " << trial << " n=" << n << " pass " << pass;
      if (pass == 0) {
        const int zeros = static_cast<int>((bf.z.array() == 0).count());
        ++activeSizes[std::min(zeros, 2)];
      }
      fallbacks += r.usedFallback;
      worst = std::max(worst, r.iterations);
      sumIterations += r.iterations;
    }
  }
  EXPECT_EQ(fallbacks, 0);
  std::printf("  %d problems (optimum with 0 / 1 / >=2 zero variables: %d / %d / %d): mean %.2f, "
              "max %d passive-set solves\n", kProblems, activeSizes[0], activeSizes[1], activeSizes[2],
              sumIterations / (2 * kProblems), worst);
  // Every kind of active set occurs.
  for (int count : activeSizes) EXPECT_GT(count, kProblems / 20);
}

TEST(ResultantDistribution, SatisfiesKktConditions) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> fingers(1, 5);
  for (int trial = 0; trial < 10000; ++trial) {
    const Problem p = randomProblem(rng, fingers(rng), logUniform(rng, 1e-3, 10), logUniform(rng, 1e-6, 1e4));
    const DistributionResult r = solve(p);
    const LeastSquares ls = buildLeastSquares(p);
    const Eigen::VectorXd z = solutionOf(r);
    const Eigen::VectorXd residual = ls.A * z - ls.b;
    const Eigen::VectorXd gradient = 2 * ls.A.transpose() * residual;  // ∇P
    const double scale = ls.b.norm() + ls.A.norm() * z.norm();
    for (int j = 0; j < z.size(); ++j) {
      const double tol = 1e-8 * ls.A.col(j).norm() * scale + 1e-300;
      EXPECT_GE(z[j], 0.0);
      EXPECT_GE(gradient[j], -tol) << "trial " << trial << " j " << j;   // dual feasibility
      if (z[j] > 0) {  // complementarity
        EXPECT_LE(std::abs(gradient[j]), tol) << "trial " << trial << " j " << j;
      }
    }
  }
}

// F and N made by pushing forces k*_i n_i are reproduced: exactly in the limit of small
// γ2, γ3; within the default match tolerance with the defaults on well-spread grasps.
TEST(ResultantDistribution, AchievableResultantIsMatched) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::uniform_int_distribution<int> fingers(1, 5);
  int matchedDefault = 0, total = 0;
  double worstTight = 0, worstDefault = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = fingers(rng);
    const double size = logUniform(rng, 1e-3, 10), magnitude = logUniform(rng, 1e-6, 1e4);
    Problem p = randomProblem(rng, n, size, magnitude);
    p.params = DistributionParams{};
    p.force.setZero();
    p.torque.setZero();
    for (int i = 0; i < n; ++i) {
      const double k = u(rng) < 0.2 ? 0.0 : magnitude * u(rng);
      const Vec3 f = k * p.fingers[i].normal.normalized();
      p.force += f;
      p.torque += (p.fingers[i].position - p.reference).cross(f);
    }
    const double L = buildLeastSquares(p).leverArm;
    const double scale = p.force.norm() + p.torque.norm() / L + 1e-300;

    const DistributionResult def = solve(p);
    ++total;
    matchedDefault += def.matched;
    worstDefault = std::max(worstDefault, (def.residualForce.norm() + def.residualTorque.norm() / L) / scale);

    Problem tight = p;
    tight.params.gamma2 = 1e-9;
    tight.params.gamma3 = 1e-12;
    const DistributionResult r = solve(tight);
    const double rel = (r.residualForce.norm() + r.residualTorque.norm() / L) / scale;
    worstTight = std::max(worstTight, rel);
    EXPECT_LT(rel, 1e-5) << "trial " << trial << " n=" << n;
    EXPECT_TRUE(r.matched);
  }
  std::printf("  residual/resultant: worst %.2e (γ2=1e-9, γ3=1e-12), worst %.2e with defaults; "
              "defaults matched %d of %d\n", worstTight, worstDefault, matchedDefault, total);
  EXPECT_GE(matchedDefault, total * 95 / 100);
}

TEST(ResultantDistribution, UnachievableResultantIsReportedAndNeverPulls) {
  // One finger pushing +z; asked to pull the part along −z: nothing can be done.
  std::vector<FingerContact> one{{Vec3(0, 0, -0.05), Vec3(0, 0, 1), 2.0}};
  DistributionResult r = hg::grasp::distributeResultant(one, Vec3(0, 0, -3), Vec3::Zero(), Vec3::Zero());
  EXPECT_TRUE(r.valid);
  EXPECT_FALSE(r.matched);
  EXPECT_EQ(r.k[0], 0.0);
  EXPECT_NEAR(r.residualForce.z(), -3, 1e-12);
  // Pushing along +z works; a sideways component stays unmatched.
  r = hg::grasp::distributeResultant(one, Vec3(1, 0, 3), Vec3::Zero(), Vec3(0, 0, -0.05));
  EXPECT_NEAR(r.k[0], 3, 3e-3);
  EXPECT_FALSE(r.matched);
  EXPECT_NEAR(r.residualForce.x(), 1, 1e-12);
}

// A slowly rotating resultant gives a continuous k_i sequence: the largest jump per step
// shrinks in proportion to the step (Lipschitz), through every change of active set.
TEST(ResultantDistribution, RotatingResultantGivesContinuousForces) {
  std::mt19937_64 rng(11);
  int activeSetChanges = 0;
  double worstJump = 0, worstRatio = 0;
  for (int n = 1; n <= 5; ++n) {
    for (int grasp = 0; grasp < 6; ++grasp) {
      Problem p = randomProblem(rng, n, 0.05, 10);
      p.params = DistributionParams{};
      const Vec3 axis = randomUnit(rng), axis2 = randomUnit(rng);
      const Vec3 f0 = 8 * randomUnit(rng), n0 = 0.3 * randomUnit(rng);
      double jumps[2] = {0, 0};
      double meanIterations = 0;
      for (int refine = 0; refine < 2; ++refine) {
        const int steps = refine == 0 ? 400 : 4000;
        const double h = 2 * M_PI / steps;
        ResultantDistributor distributor;
        DistributionResult last;
        std::uint8_t lastSet = 0;
        for (int s = 0; s <= steps; ++s) {
          const double a = s * h;
          const Vec3 force = Eigen::AngleAxisd(a, axis) * f0;
          const Vec3 torque = Eigen::AngleAxisd(1.3 * a, axis2) * n0;
          const DistributionResult& r = distributor.solve(p.fingers, force, torque, p.reference);
          ASSERT_TRUE(r.valid);
          if (s > 0) {
            double jump = std::abs(r.kGrasp - last.kGrasp);
            for (int i = 0; i < n; ++i) jump = std::max(jump, std::abs(r.k[i] - last.k[i]));
            jumps[refine] = std::max(jumps[refine], jump / (h * f0.norm()));
            if (refine == 1 && r.passiveSet != lastSet) ++activeSetChanges;
            if (refine == 1) meanIterations += r.iterations;
          }
          last = r;
          lastSet = r.passiveSet;
        }
        if (refine == 1) meanIterations /= steps;
      }
      // Jump per unit step bounded, and no worse with 10x finer steps (no discontinuity:
      // a jump would stay the same size as the step shrinks, i.e. grow 10x here).
      EXPECT_LT(jumps[0], 50.0) << "n=" << n;
      EXPECT_LT(jumps[1], 1.5 * jumps[0] + 1e-9) << "n=" << n;
      EXPECT_LT(meanIterations, 1.5) << "warm start, n=" << n;
      worstJump = std::max(worstJump, jumps[0]);
      worstRatio = std::max(worstRatio, jumps[1] / std::max(jumps[0], 1e-300));
    }
  }
  EXPECT_GT(activeSetChanges, 20);
  std::printf("  max |dk| / (|F| dθ) = %.2f; with 10x finer steps %.2f times that; %d active-set changes\n",
              worstJump, worstRatio, activeSetChanges);
}

// Bounded output. Any point at least as good as z = 0 has P ≤ P(0) = |F|² + γ1 |N|², so the
// net force and torque the fingers add exceed the resultant by at most √P(0) (in force
// units); single k_i may be larger than the resultant only as internal forces (levers),
// which γ2, γ3 keep finite: at most a few hundred times the resultant in these tests.
double g_worstRatio = 0;
void expectBounded(const Problem& p, const DistributionResult& r, const char* what) {
  ASSERT_TRUE(r.valid) << what;
  const double L = r.leverArm;
  const double scale = p.force.norm() + p.torque.norm() / L;
  const double p0 = std::sqrt(p.force.squaredNorm() + r.gamma1 * p.torque.squaredNorm());
  const Vec3 netForce = p.force - r.residualForce, netTorque = p.torque - r.residualTorque;
  EXPECT_LE(netForce.norm(), (p.force.norm() + p0) * (1 + 1e-9)) << what;
  EXPECT_LE(std::sqrt(r.gamma1) * netTorque.norm(), (std::sqrt(r.gamma1) * p.torque.norm() + p0) * (1 + 1e-9)) << what;
  for (int i = 0; i < r.fingers; ++i) {
    EXPECT_LE(r.k[i], 1e3 * scale) << what;
    g_worstRatio = std::max(g_worstRatio, r.k[i] / scale);
  }
}

TEST(ResultantDistribution, ExtremeMagnitudesAndSizes) {
  std::mt19937_64 rng(5);
  for (double magnitude : {1e-6, 1e-3, 1.0, 1e2, 1e4}) {
    for (double size : {1e-3, 1e-2, 1.0, 10.0}) {
      for (int n = 1; n <= 5; ++n) {
        for (int rep = 0; rep < 8; ++rep) {
          Problem p = randomProblem(rng, n, size, magnitude);
          if (rep == 0) p.params = DistributionParams{};
          if (rep == 1) p.params.gamma1 = 1e6 / (size * size);  // stiff torque weight
          if (rep == 2) p.params.gamma2 = 1e3;                   // stiff proportionality
          if (rep == 3) p.params.gamma3 = 1e-12;                 // floor of γ3
          if (rep == 4) for (auto& f : p.fingers) f.graspForce = 1e4;
          if (rep == 5) p.reference += Vec3(100 * size, 0, 0);  // far reference point
          const DistributionResult r = solve(p);
          expectOptimal(p, r, "extreme");
          expectBounded(p, r, "extreme");
        }
      }
    }
  }
  std::printf("  largest k_i / (|F| + |N|/L): %.1f\n", g_worstRatio);
}

Problem boxGrasp() {
  Problem p;
  p.reference = Vec3(0, 0, 0.01);
  p.force = Vec3(0.3, -0.2, 4.0);
  p.torque = Vec3(0.02, 0.05, -0.01);
  return p;
}

TEST(ResultantDistribution, DegenerateGrasps) {
  // Five fingers on one face: all normals equal (+z), spread over the face.
  {
    Problem p = boxGrasp();
    for (int i = 0; i < 5; ++i)
      p.fingers.push_back({Vec3(0.01 * std::cos(i * 1.2566), 0.01 * std::sin(i * 1.2566), -0.02),
                           Vec3(0, 0, 1), 1.0 + i});
    const DistributionResult r = solve(p);
    expectOptimal(p, r, "one face");
    expectBounded(p, r, "one face");
    EXPECT_NEAR(r.residualForce.x(), 0.3, 1e-12);  // no friction: sideways stays unmatched
    Problem up = p;
    up.force = Vec3(0, 0, 4);
    up.torque = Vec3::Zero();
    const DistributionResult ru = solve(up);  // a pure push along the normal through the reference
    expectOptimal(up, ru, "one face, push");
    EXPECT_TRUE(ru.matched);
  }
  // Two fingers on opposite edges of a box (normals along the edges' bisectors).
  {
    Problem p = boxGrasp();
    p.fingers.push_back({Vec3(-0.03, 0, 0.02), Vec3(1, 0, -1), 2.0});
    p.fingers.push_back({Vec3(0.03, 0, 0.02), Vec3(-1, 0, -1), 2.0});
    const DistributionResult r = solve(p);
    expectOptimal(p, r, "opposite edges");
    expectBounded(p, r, "opposite edges");
  }
  // Two fingers exactly opposed on a line: the resultant along the line goes to one.
  {
    Problem p = boxGrasp();
    p.fingers.push_back({Vec3(-0.03, 0, 0.01), Vec3(1, 0, 0), 2.0});
    p.fingers.push_back({Vec3(0.03, 0, 0.01), Vec3(-1, 0, 0), 2.0});
    p.force = Vec3(-5, 0, 0);
    p.torque.setZero();
    const DistributionResult r = solve(p);
    expectOptimal(p, r, "opposed");
    EXPECT_TRUE(r.matched);
    EXPECT_NEAR(r.k[1], 5, 5 * 1e-3);
    EXPECT_LT(r.k[0], 1e-6);
  }
  // Coincident fingers (2..5 at the same point with the same normal), and coincident
  // positions with different normals.
  for (int n = 2; n <= 5; ++n) {
    Problem p = boxGrasp();
    for (int i = 0; i < n; ++i) p.fingers.push_back({Vec3(0, 0, -0.02), Vec3(0, 0, 1), 1.0 * i});
    DistributionResult r = solve(p);
    expectOptimal(p, r, "coincident");
    expectBounded(p, r, "coincident");
    for (int i = 0; i < n; ++i) p.fingers[i].normal = Vec3(0.1 * i, 0, 1);
    r = solve(p);
    expectOptimal(p, r, "same point");
  }
  // Zero grasping forces; a zero normal; zero resultant; all fingers on the reference.
  {
    Problem p = boxGrasp();
    p.fingers.push_back({Vec3(-0.03, 0, 0.01), Vec3(1, 0, 0.2), 0});
    p.fingers.push_back({Vec3(0.03, 0, 0.01), Vec3(-1, 0, 0.2), 0});
    p.fingers.push_back({Vec3(0, 0.03, 0.0), Vec3(0, -1, 0.5), 0});
    DistributionResult r = solve(p);
    expectOptimal(p, r, "zero grasp forces");
    EXPECT_EQ(r.kGrasp, 0.0);
    p.fingers[1].normal.setZero();
    r = solve(p);
    expectOptimal(p, r, "zero normal");
    EXPECT_TRUE(r.forces[1].isZero());
    p.force.setZero();
    p.torque.setZero();
    r = solve(p);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(r.k[i], 0.0);
    EXPECT_TRUE(r.matched);
    Problem q = boxGrasp();
    std::mt19937_64 rng(1);
    for (int i = 0; i < 3; ++i) q.fingers.push_back({q.reference, randomUnit(rng), 1.0});
    r = solve(q);
    expectOptimal(q, r, "fingers on the reference");
  }
}

TEST(ResultantDistribution, RejectsInvalidInputWithoutNaN) {
  std::vector<FingerContact> none;
  std::vector<FingerContact> six(6, FingerContact{Vec3(0, 0, 0.1), Vec3(0, 0, -1), 1.0});
  std::vector<FingerContact> two(2, FingerContact{Vec3(0, 0, 0.1), Vec3(0, 0, -1), 1.0});
  EXPECT_FALSE(hg::grasp::distributeResultant(none, Vec3(0, 0, 1), Vec3::Zero(), Vec3::Zero()).valid);
  EXPECT_FALSE(hg::grasp::distributeResultant(six, Vec3(0, 0, 1), Vec3::Zero(), Vec3::Zero()).valid);
  const double nan = std::nan("");
  EXPECT_FALSE(hg::grasp::distributeResultant(two, Vec3(0, nan, 1), Vec3::Zero(), Vec3::Zero()).valid);
  two[1].graspForce = INFINITY;
  const DistributionResult r = hg::grasp::distributeResultant(two, Vec3(0, 0, 1), Vec3::Zero(), Vec3::Zero());
  EXPECT_FALSE(r.valid);
  EXPECT_EQ(r.fingers, 0);
  expectFiniteAndNonNegative(r);
  two[1].graspForce = 1;
  const DistributionResult huge = hg::grasp::distributeResultant(two, Vec3(0, 0, 1e300), Vec3::Zero(), Vec3::Zero());
  expectFiniteAndNonNegative(huge);
}

TEST(ResultantDistribution, FallbackEnumerationIsExact) {
  std::mt19937_64 rng(23);
  for (int trial = 0; trial < 300; ++trial) {
    Problem p = randomProblem(rng, 1 + trial % 5, 0.05, 10);
    const DistributionResult normal = solve(p);
    p.params.maxIterations = trial % 3;  // 0: enumerate at once; 1, 2: after a few steps
    const DistributionResult r = solve(p);
    expectOptimal(p, r, "fallback");
    if (r.usedFallback) {
      EXPECT_GE(r.iterations, (1 << (r.fingers + 1)) - 1);
    }
    if (p.params.maxIterations == 0 && r.passiveSet != 0) {  // z = 0 needs no solve at all
      EXPECT_TRUE(r.usedFallback);
    }
    EXPECT_NEAR(r.cost, normal.cost, 1e-9 * normal.cost + 1e-300);
  }
}

TEST(ResultantDistribution, SolveDoesNotAllocate) {
  std::mt19937_64 rng(29);
  std::vector<Problem> problems;
  for (int i = 0; i < 500; ++i) problems.push_back(randomProblem(rng, 1 + i % 5, logUniform(rng, 1e-3, 10), logUniform(rng, 1e-6, 1e4)));
  problems[7].params.maxIterations = 0;  // the fallback too
  problems[8].fingers.clear();           // and a rejected input
  problems[9].force.x() = std::nan("");
  ResultantDistributor distributor;
  double checksum = 0;
  const long before = hg::test::allocations();
  for (const Problem& p : problems) {
    distributor.setParams(p.params);
    checksum += distributor.solve(p.fingers, p.force, p.torque, p.reference).cost;
    checksum += hg::grasp::distributeResultant(p.fingers, p.force, p.torque, p.reference, p.params).cost;
  }
  const long after = hg::test::allocations();
  EXPECT_EQ(after - before, 0);
  EXPECT_TRUE(std::isfinite(checksum));
}

// γ2 trades the resultant away: two opposed fingers keep 1 − γ2/(2 + γ2) of it.
TEST(ResultantDistribution, ProportionalityWeightTradesTheResultant) {
  for (double gamma2 : {1e-3, 1e-1, 1.0, 10.0}) {
    Problem p;
    p.fingers.push_back({Vec3(-0.03, 0, 0), Vec3(1, 0, 0), 2.0});
    p.fingers.push_back({Vec3(0.03, 0, 0), Vec3(-1, 0, 0), 2.0});
    p.force = Vec3(6, 0, 0);
    p.params.gamma2 = gamma2;
    p.params.gamma3 = 1e-12;
    const DistributionResult r = solve(p);
    expectOptimal(p, r, "trade");
    const double kept = (r.forces[0] + r.forces[1]).x() / 6;
    EXPECT_NEAR(kept, 1 - gamma2 / (2 + gamma2), 1e-9);
  }
}

// Eqs 10/11: the resultant k_d d_d + f_e goes, whole, to the finger whose grasping force
// it increases; the other finger keeps its grasping force.
TEST(ResultantDistribution, OneDofDistributionOnALine) {
  const double kg = 800, kd = 800;
  const double d1 = -0.0025, d2 = 0.0025;  // both springs compressed by f_g / k_g = 2.5 mm
  for (double dd : {-0.004, -0.001, 0.0, 0.001, 0.004}) {
    for (double fe : {-3.0, 0.0, 1.5}) {
      const double resultant = kd * dd + fe;
      const auto line = hg::grasp::distributeOnLine(kg, d1, d2, kd, dd, fe);
      EXPECT_EQ(line.toFinger1, resultant <= 0);
      if (resultant <= 0) {  // eq 10
        EXPECT_DOUBLE_EQ(line.f1, -(kg * d1 + kd * dd + fe));
        EXPECT_DOUBLE_EQ(line.f2, -kg * d2);
      } else {  // eq 11
        EXPECT_DOUBLE_EQ(line.f1, -kg * d1);
        EXPECT_DOUBLE_EQ(line.f2, -(kg * d2 + kd * dd + fe));
      }
      // Grasping forces never decrease; the fingers' total changes by −R on them.
      EXPECT_GE(line.f1, -kg * d1);
      EXPECT_LE(line.f2, -kg * d2);
      EXPECT_NEAR(line.f1 + line.f2, -kg * (d1 + d2) - resultant, 1e-12);

      // The 6-DOF distribution agrees in its limit: finger 1 pushes the part towards −x
      // (normal −x), finger 2 towards +x; the part needs R on it from the fingers.
      Problem p;
      p.fingers.push_back({Vec3(0.03, 0, 0), Vec3(-1, 0, 0), kg * -d1});
      p.fingers.push_back({Vec3(-0.03, 0, 0), Vec3(1, 0, 0), kg * d2});
      p.force = Vec3(resultant, 0, 0);
      p.params.gamma2 = 1e-9;
      p.params.gamma3 = 1e-12;
      const DistributionResult r = solve(p);
      EXPECT_NEAR(r.k[0], line.f1 - (-kg * d1), 1e-6);
      EXPECT_NEAR(r.k[1], -(line.f2 - (-kg * d2)), 1e-6);
    }
  }
}

// Median solve time; run with --gtest_also_run_disabled_tests.
TEST(ResultantDistribution, DISABLED_Timing) {
  using Clock = std::chrono::steady_clock;
  std::mt19937_64 rng(31);
  for (int n : {1, 2, 3, 4, 5}) {
    std::vector<Problem> problems;
    for (int i = 0; i < 20000; ++i) {
      problems.push_back(randomProblem(rng, n, 0.05, 10));
      problems.back().params = DistributionParams{};
    }
    std::vector<double> cold, warm;
    ResultantDistributor distributor;
    double checksum = 0;
    for (const Problem& p : problems) {
      distributor.reset();
      const auto t0 = Clock::now();
      checksum += distributor.solve(p.fingers, p.force, p.torque, p.reference).cost;
      cold.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    }
    // Warm: a slowly rotating resultant on one grasp per 1000 ticks.
    const Vec3 axis = randomUnit(rng);
    for (std::size_t i = 0; i < problems.size(); ++i) {
      const Problem& p = problems[i / 1000 * 1000];
      const Vec3 force = Eigen::AngleAxisd(1e-3 * i, axis) * p.force;
      const auto t0 = Clock::now();
      checksum += distributor.solve(p.fingers, force, p.torque, p.reference).cost;
      warm.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    }
    auto median = [](std::vector<double>& v) {
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    auto p99 = [](std::vector<double>& v) {
      std::nth_element(v.begin(), v.begin() + v.size() * 99 / 100, v.end());
      return v[v.size() * 99 / 100];
    };
    std::printf("  n=%d: cold median %.3f us (p99 %.3f), warm median %.3f us (p99 %.3f) [%g]\n", n,
                median(cold), p99(cold), median(warm), p99(warm), checksum > 0 ? 1.0 : 0.0);
  }
}

}  // namespace
