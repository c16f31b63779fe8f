// The two-finger grasp of Maekawa & Hollerbach (sections 2-3) with DESIGN.md's errata:
// each force law against its equation, the state sequence of Fig. 3/Fig. 6, continuity
// of the vertical wrist force at lift, return on release from GRASP, hysteresis, the
// hardening (non-attractive forces, filtered rates, degenerate frames, NaN samples),
// sweeps of rate, stiffness, size, mass and orientation, no allocation, and that parts
// nobody touches cost no query.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "alloc_counter.hpp"
#include "hapticgrasp/grasp/grasp_cylinder_experiment.hpp"
#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/grasp/two_finger_grasp.hpp"
#include "hapticgrasp/math/rpy.hpp"
#include "test_shapes.hpp"

namespace hg::grasp {
namespace {

using S = GraspState;
using geometry::MassSpec;
constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------
// A cylinder (the paper's, scaled) in a scene, and a scripted hand that runs Fig. 6 on it.

struct Case {
  double scale = 1;        // the paper's 0.1 m x 0.4 m cylinder times this
  double mass_kg = 2;
  Mat3 rotation = Eigen::AngleAxisd(-kPi / 2, Vec3::UnitX()).toRotationMatrix();  // axis along y
  Vec3 position = Vec3(0.4, 0, 0.3);
  double stiffness = 1;    // K_c, K_g, K_ox, K_oe times this
  double damping = 1;      // B_c, B_g times this
  geometry::Backend backend = geometry::Backend::Auto;
};

GraspParameters parametersFor(const Case& s) {
  GraspParameters k;
  k.K_c *= s.stiffness;
  k.K_g *= s.stiffness;
  k.K_ox *= s.stiffness;
  k.K_oe *= s.stiffness;
  k.B_c *= s.damping;
  k.B_g *= s.damping;
  return k;
}

ScenePart cylinderFor(const Case& s) {
  return makeScenePart(test::cylinderPart(100 * s.scale, 400 * s.scale), MassSpec::mass(s.mass_kg),
                       PartPose{s.rotation, s.position}, s.backend);
}

ScenePtr sceneOf(std::vector<ScenePart> parts) { return std::make_shared<const Scene>(std::move(parts)); }

// A hand given in the part's frame: fingertips and wrist as points of the object frame.
HandSample handIn(const PartPose& pose, const Vec3& index, const Vec3& thumb, const Vec3& wrist = Vec3(0, -0.1, 0)) {
  HandSample h;
  h.index = pose.pointToAbsolute(index);
  h.thumb = pose.pointToAbsolute(thumb);
  h.wrist = pose.pointToAbsolute(wrist);
  return h;
}

// Where the fingertips go, in the cylinder's frame (axis z): across the diameter along x,
// index at +x; the wrist off to -y.
struct Grip {
  double r, halfLength;
  double depth;    // fingertip depth while touching
  double gap;      // open fingertips' gap to the surface (> d_h/2, so opening releases)
  double wrist;    // wrist's distance from the fingertips' line
  double squeeze;  // each fingertip, further in once grasped
  double liftHeight;  // where the springs carry the weight: M |g| / K_ox
};

Grip gripFor(const Case& s, const GraspParameters& k) {
  Grip g;
  g.r = 0.05 * s.scale;
  g.halfLength = 0.2 * s.scale;
  // Less than d_h / 2: the fingertip that came first is out of the part when the grasp
  // opens by d_h, so the release leaves both fingertips outside (FREE).
  g.depth = std::min(0.1 * g.r, 0.4 * k.d_h);
  g.gap = std::max(0.2 * g.r, k.d_h);
  g.wrist = std::max(0.1, 2 * g.r);
  g.squeeze = g.depth / 2;
  g.liftHeight = s.mass_kg * k.gravity.norm() / k.K_ox;
  return g;
}

enum class Variant {
  Standard,             // FREE, INDEX, FREE, THUMB, GRASP, MANIPULATE, FREE
  ReturnFromGrasp,      // lifted too little: FREE, INDEX, FREE, THUMB, GRASP, FREE (return)
  CoincidentWhileFree,  // the hand starts closed, fingertips on one point
  WristOnFingerLine,    // while lifting, the wrist moves onto the fingertips' line and back
};

const std::vector<S> kStandardSequence = {S::Free,  S::IndexContact, S::Free, S::ThumbContact,
                                          S::Grasp, S::Manipulate,   S::Free};
const std::vector<S> kReturnSequence = {S::Free, S::IndexContact, S::Free, S::ThumbContact, S::Grasp, S::Free};

HandKey keyAt(const std::vector<HandKey>& keys, double t) {
  auto after = std::upper_bound(keys.begin(), keys.end(), t, [](double x, const HandKey& k) { return x < k.t; });
  const HandKey &a = *(after - 1), &b = *after;
  const double u = (t - a.t) / (b.t - a.t);
  return {t, (1 - u) * a.index + u * b.index, (1 - u) * a.thumb + u * b.thumb, (1 - u) * a.wrist + u * b.wrist,
          (1 - u) * a.shift + u * b.shift, (1 - u) * a.turn + u * b.turn};
}

HandScript paperScript(const Case& s, const GraspParameters& k, Variant variant = Variant::Standard) {
  const Grip g = gripFor(s, k);
  const double open = g.r + g.gap, in = g.r - g.depth, squeezed = in - g.squeeze;
  const bool returns = variant == Variant::ReturnFromGrasp;
  const double lift = returns ? 0.5 * g.liftHeight : 1.5 * g.liftHeight + 0.01 * s.scale;
  const Vec3 up(0, 0, lift), carry(0.3 * s.scale, 0.1 * s.scale, 0);
  std::vector<HandKey> keys;
  const auto key = [&](double t, double index, double thumb, double z = 0, Vec3 shift = Vec3::Zero(),
                       double turn = 0) {
    keys.push_back({t, {index, 0, z}, {-thumb, 0, z}, {0, -g.wrist, z}, shift, turn});
  };
  key(0.0, open, open);
  key(0.1, open, open);
  key(0.2, in, open);                       // index contact
  key(0.3, in, open, 0.2 * g.halfLength);  // tracing
  key(0.4, in, open);
  key(0.5, open, open);                     // index detach
  key(0.6, open, in);                       // thumb contact
  key(0.7, in, in);                         // grasp
  key(0.8, squeezed, squeezed);
  if (returns) {
    key(1.3, squeezed, squeezed, 0, up);
    key(1.4, open, open, 0, up);           // release: the part returns
    key(1.5, open, open, 0, up);
  } else {
    key(1.3, squeezed, squeezed, 0, up);    // lift
    key(1.6, squeezed, squeezed, 0, up + carry, kPi / 2);  // carry and turn
    key(1.7, squeezed, squeezed, 0, 0.5 * up + carry, kPi / 2);
    key(1.8, open, open, 0, 0.5 * up + carry, kPi / 2);    // release, the part stays
    key(1.9, open, open, 0, 0.5 * up + carry, kPi / 2);
  }
  if (variant == Variant::CoincidentWhileFree) {
    // Closed hand: both fingertips on one point well outside, then open (still FREE).
    const double R = open;
    keys[0].index = keys[0].thumb = Vec3(0, -3 * R, 0);
  }
  if (variant == Variant::WristOnFingerLine) {
    std::vector<HandKey> extra;
    for (double t : {0.95, 1.0, 1.1, 1.15}) extra.push_back(keyAt(keys, t));
    extra[1].wrist = extra[2].wrist = 0.5 * (extra[1].index + extra[1].thumb) + Vec3(0.3 * g.r, 0, 0);
    keys.insert(std::upper_bound(keys.begin(), keys.end(), 0.9, [](double x, const HandKey& k) { return x < k.t; }),
                extra.begin(), extra.end());
  }
  const Vec3 pivot = s.position;  // the grasp midpoint at rest: the cylinder's centre
  return HandScript(std::move(keys), PartPose{s.rotation, s.position}, pivot);
}

// ---------------------------------------------------------------------------------------
// Running a script.

struct RunOptions {
  double dt = 5e-4;
  double jitter = 0;      // dt of each tick uniform in dt * [1 - jitter, 1 + jitter]
  int invalidEvery = 0;   // every n-th sample gets a NaN or Inf
  unsigned seed = 7;
};

struct Trace {
  std::vector<S> states;            // the sequence, repeats removed
  std::vector<double> transitionTimes;
  std::vector<std::uint32_t> transitionEvents;
  std::uint32_t events = 0;         // everything raised
  bool finite = true;
  bool invalidTicksBehaved = true;  // zero force, state kept, no event
  int invalidTicks = 0;
  double maxFinger = 0, maxGrasp = 0, maxWrist = 0, maxMoment = 0;
  double maxSpeed = 0, maxDt = 0;
  double liftJump = -1, verticalBeforeLift = 0, verticalAtLift = 0;
  long queries = 0, queriesHolding = 0;  // all; in GRASP and MANIPULATE after the grasp tick
  PartPose finalPose;
  std::vector<GraspOutput> outputs;  // when asked for; their `poses` show the last tick only,
  std::vector<PartPose> pose0;       // so part 0's pose is copied each tick
};

Trace run(TwoFingerGrasp& grasp, const HandScript& script, const RunOptions& o = {}, bool keep = false) {
  Trace r;
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> jitter(1 - o.jitter, 1 + o.jitter);
  const Vec3 down = grasp.parameters().gravity.normalized();
  S state = grasp.state();
  r.states.push_back(state);
  double t = 0, dt = 0, lastVertical = 0;
  HandSample last = script.at(0);
  for (long n = 0; t <= script.duration(); ++n) {
    HandSample s = script.at(t);
    if (n > 0) {
      r.maxSpeed = std::max({r.maxSpeed, (s.index - last.index).norm() / dt, (s.thumb - last.thumb).norm() / dt});
      r.maxDt = std::max(r.maxDt, dt);
    }
    last = s;
    const bool invalid = o.invalidEvery > 0 && n % o.invalidEvery == o.invalidEvery - 1;
    if (invalid) {
      switch ((n / o.invalidEvery) % 5) {
        case 0: s.index.x() = kNaN; break;
        case 1: s.thumb.y() = kInf; break;
        case 2: s.wrist.z() = -kInf; break;
        case 3: s.wristRotation(1, 2) = kNaN; break;
        default: s.t = kNaN; break;
      }
    }
    const GraspOutput out = grasp.step(s, dt);
    if (keep) {
      r.outputs.push_back(out);
      r.pose0.push_back(out.poses[0]);
    }
    if (invalid) {
      ++r.invalidTicks;
      r.invalidTicksBehaved &= !out.validSample && out.state == state && out.events == 0 &&
                               out.f_index.isZero(0) && out.f_thumb.isZero(0) && out.f_wrist.isZero(0) &&
                               out.m_wrist.isZero(0) && out.f_grasp == 0;
    } else {
      r.invalidTicksBehaved &= out.validSample;
    }
    r.finite &= out.f_index.allFinite() && out.f_thumb.allFinite() && out.f_wrist.allFinite() &&
                out.m_wrist.allFinite() && std::isfinite(out.f_grasp);
    for (const PartPose& p : out.poses) r.finite &= p.rotation.allFinite() && p.position.allFinite();
    r.maxFinger = std::max({r.maxFinger, out.f_index.norm(), out.f_thumb.norm()});
    r.maxGrasp = std::max(r.maxGrasp, out.f_grasp);
    r.maxWrist = std::max(r.maxWrist, out.f_wrist.norm());
    r.maxMoment = std::max(r.maxMoment, out.m_wrist.norm());
    r.queries += out.queries;
    if ((out.state == S::Grasp || out.state == S::Manipulate) && !(out.events & kGrasp))
      r.queriesHolding += out.queries;
    r.events |= out.events;
    if (out.validSample) {
      const double vertical = out.f_wrist.dot(down);
      if (out.events & kLift) {
        r.liftJump = std::abs(vertical - lastVertical);
        r.verticalBeforeLift = lastVertical;
        r.verticalAtLift = vertical;
      }
      lastVertical = vertical;
    }
    if (out.state != state) {
      r.states.push_back(out.state);
      r.transitionTimes.push_back(t);
      r.transitionEvents.push_back(out.events);
    }
    state = out.state;
    dt = o.dt * (o.jitter > 0 ? jitter(rng) : 1.0);
    t += dt;
  }
  r.finalPose = grasp.poses()[0];
  return r;
}

std::string describe(const std::vector<S>& states) {
  std::string text;
  for (S s : states) text += std::string(text.empty() ? "" : " > ") + toString(s);
  return text;
}

// Forces no larger than the laws allow for this hand: eq 9 and 24 with the fastest
// fingertip, eq 23 up to the lift (one tick late at most) and eq 30.
void expectBounded(const Trace& r, const Case& s, const GraspParameters& k, const std::string& what) {
  const Grip g = gripFor(s, k);
  const double finger = std::max((k.K_c + k.B_c * r.maxSpeed) * std::sqrt(2 * g.depth),
                                 (k.K_g + k.B_g * 2 * r.maxSpeed) * std::sqrt(2 * g.r + k.d_h));
  const double weight = s.mass_kg * k.gravity.norm();
  const double wrist = weight + k.K_ox * (r.maxSpeed * r.maxDt + 2 * g.depth);
  const double moment = weight * (2 * g.halfLength + g.wrist + 2 * g.r) + k.K_oe * kPi;
  EXPECT_TRUE(r.finite) << what;
  EXPECT_LE(r.maxFinger, 1.0001 * finger) << what;
  EXPECT_LE(r.maxWrist, 1.0001 * wrist) << what;
  EXPECT_LE(r.maxMoment, 1.0001 * moment) << what;
  EXPECT_GT(r.maxFinger, 0) << what;
}

Trace runSetup(const Case& s, const RunOptions& o = {}, Variant v = Variant::Standard) {
  const GraspParameters k = parametersFor(s);
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  Trace r = run(grasp, paperScript(s, k, v), o);
  expectBounded(r, s, k, describe(r.states));
  return r;
}

// ---------------------------------------------------------------------------------------
// The force laws, one by one.

TEST(ForceLaws, Eq9ContactForceAndItsClamp) {
  GraspParameters k;
  const Vec3 p(0, 0, -4e-3);  // 4 mm into a part whose surface normal is +z
  EXPECT_LT((contactForce(p, Vec3::UnitZ(), 0, k) - Vec3(0, 0, 130 * std::sqrt(4e-3))).norm(), 1e-12);
  // Pressing in (d|p|/dt > 0) adds damping; leaving fast would pull: clamped to zero.
  EXPECT_NEAR(contactForce(p, Vec3::UnitZ(), 0.2, k).z(), (130 + 100 * 0.2) * std::sqrt(4e-3), 1e-12);
  EXPECT_NEAR(contactForce(p, Vec3::UnitZ(), -1.0, k).z(), (130 - 100) * std::sqrt(4e-3), 1e-12);
  EXPECT_EQ(contactForce(p, Vec3::UnitZ(), -1.31, k), Vec3::Zero());
  EXPECT_EQ(contactForce(Vec3::Zero(), Vec3::UnitZ(), 5, k), Vec3::Zero());
}

TEST(ForceLaws, Eq24GraspingForceAndItsClamps) {
  GraspParameters k;  // K_g 1000, B_g 800, d_h 2 mm
  // At A (the distance at the transition) the force steps up to K_g sqrt(d_h) (A->B).
  EXPECT_NEAR(graspingForce(0.1, 0, 0.1, k), 1000 * std::sqrt(2e-3), 1e-12);
  EXPECT_NEAR(graspingForce(0.097, 0, 0.1, k), 1000 * std::sqrt(5e-3), 1e-12);    // squeezed (B->C)
  EXPECT_NEAR(graspingForce(0.097, -0.05, 0.1, k), 1040 * std::sqrt(5e-3), 1e-12);  // closing: damping
  EXPECT_NEAR(graspingForce(0.102, 0, 0.1, k), 0.0, 1e-5);  // D: zero at d_bar + d_h (to rounding)
  EXPECT_EQ(graspingForce(0.105, 0, 0.1, k), 0.0);      // beyond: no negative travel
  EXPECT_EQ(graspingForce(0.099, 1.3, 0.1, k), 0.0);    // opening fast: would pull, clamped
}

TEST(ForceLaws, Eq23SpringsEq30GravityEq29Corrected) {
  GraspParameters k;
  PartPose held{math::paperRotation(Vec3(0.1, -0.2, 0.3)).transpose(), Vec3(1, 2, 3)};
  PartPose moved = held;
  moved.position += Vec3(0.01, -0.02, 0.005);
  const Vec3 turn(0.02, -0.01, 0.03);
  moved.rotation = math::fromRotationVector(turn) * held.rotation;
  const Wrench w = springWrench(moved, held, k);
  EXPECT_LT((w.force + 2000 * Vec3(0.01, -0.02, 0.005)).norm(), 1e-9);
  EXPECT_LT((w.moment + 20 * turn).norm(), 1e-12);
  // The paper's RPY form: -K_oe (xi - xi_bar), wrapped.
  k.rotationalSpring = RotationalSpring::PaperRpy;
  const Vec3 xi = math::paperRpy(moved.rotation.transpose()), xiBar = math::paperRpy(held.rotation.transpose());
  EXPECT_LT((springWrench(moved, held, k).moment + 20 * (xi - xiBar)).norm(), 1e-12);
  // Across yaw +/-180 degrees the printed difference would jump by 2 pi; wrapped, it does not.
  PartPose a{math::paperRotation(Vec3(0, 0, kPi - 0.01)).transpose(), Vec3::Zero()};
  PartPose b{math::paperRotation(Vec3(0, 0, -kPi + 0.01)).transpose(), Vec3::Zero()};
  EXPECT_NEAR(springWrench(b, a, k).moment.norm(), 20 * 0.02, 1e-9);

  // Eq 30: weight at the wrist, moment of the weight about it.
  const Vec3 x_g(0.1, 0, 0);
  const Wrench gw = gravityWrench(held, x_g, 2.0, Vec3(1, 2, 3.2), k);
  EXPECT_LT((gw.force - 2.0 * k.gravity).norm(), 1e-12);
  EXPECT_LT((gw.moment - (held.pointToAbsolute(x_g) - Vec3(1, 2, 3.2)).cross(2.0 * k.gravity)).norm(), 1e-12);
  // Eq 29 corrected: a wrist force down along g of M|g| carries the weight; up does not.
  const double weight = 2.0 * k.gravity.norm();
  EXPECT_TRUE(springsCarryWeight(Vec3(0, 0, -weight), 2.0, k));
  EXPECT_FALSE(springsCarryWeight(Vec3(0, 0, -0.999 * weight), 2.0, k));
  EXPECT_FALSE(springsCarryWeight(Vec3(0, 0, weight), 2.0, k));
}

TEST(RateFilter, BoundedByCutOffTimesJumpAndHoldsOverTinyTicks) {
  RateFilter f;
  f.reset(0);
  // A 1 mm jump in one 10 ns tick: the raw rate is 1e5 m/s; the filtered one <= w * 1 mm.
  const double rate = f.update(1e-3, 1e-8, 100);
  EXPECT_GT(rate, 0);
  EXPECT_LE(rate, 2 * kPi * 100 * 1e-3);
  // Zero-length ticks accumulate instead of dividing by zero.
  RateFilter g;
  g.reset(0);
  EXPECT_EQ(g.update(1.0, 0, 100), 0.0);
  EXPECT_EQ(g.update(1.0, 1e-12, 100), 0.0);
  EXPECT_TRUE(std::isfinite(g.update(2.0, 1e-3, 100)));
  // A steady ramp is followed exactly, whatever dt (exact discretisation).
  RateFilter h;
  h.reset(0);
  double x = 0, last = 0;
  for (int i = 0; i < 2000; ++i) {
    const double dt = 1e-4 * (1 + 0.5 * std::sin(i));
    x += 0.3 * dt;
    last = h.update(x, dt, 100);
  }
  EXPECT_NEAR(last, 0.3, 1e-9);
}

// ---------------------------------------------------------------------------------------
// Eqs 2-9 in the state machine: contact with a posed part.

TEST(TwoFingerGrasp, ContactForceUsesThePartPose) {
  const Case s;  // lying along y: the object's x is absolute x, its -y is absolute up
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}));
  const PartPose pose{s.rotation, s.position};
  HandSample h = handIn(pose, Vec3(0.08, 0, 0), Vec3(-0.08, 0, 0));
  EXPECT_EQ(grasp.step(h, 0).state, S::Free);
  // Object -y is absolute +z: the index pressed 3 mm into the top (object -y side).
  h.index = pose.pointToAbsolute(Vec3(0, -(0.05 - 3e-3), 0.1));
  GraspOutput out = grasp.step(h, 5e-4);
  EXPECT_EQ(out.state, S::IndexContact);
  EXPECT_EQ(out.events, unsigned(kIndexContact));
  EXPECT_EQ(out.indexPart, 0);
  for (int i = 0; i < 400; ++i) out = grasp.step(h, 5e-4);  // the rate filter settles at 0
  EXPECT_LT((out.f_index - Vec3(0, 0, 130 * std::sqrt(3e-3))).norm(), 1e-9) << out.f_index.transpose();
  EXPECT_EQ(out.f_thumb, Vec3::Zero());
  EXPECT_EQ(out.f_wrist, Vec3::Zero());
}

TEST(TwoFingerGrasp, LeavingFastNeverPulls) {
  const Case s;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}));
  const PartPose pose{s.rotation, s.position};
  const Vec3 outward = pose.vectorToAbsolute(Vec3::UnitX());
  HandSample h;
  h.wrist = pose.pointToAbsolute(Vec3(0, -0.1, 0));
  h.thumb = pose.pointToAbsolute(Vec3(-0.08, 0, 0));
  const double dt = 5e-4;
  bool wouldPull = false;
  double depth = 0;
  for (int i = 0; i < 600; ++i) {
    // In at 0.1 m/s to 6 mm, out at 5 m/s.
    const double t = i * dt;
    depth = t < 0.06 ? 0.1 * t : 6e-3 - 5.0 * (t - 0.06);
    h.index = pose.pointToAbsolute(Vec3(0.05 - depth, 0, 0));
    const GraspOutput out = grasp.step(h, i ? dt : 0);
    const double along = out.f_index.dot(outward);
    EXPECT_GE(along, 0) << "t " << t;
    EXPECT_LT((out.f_index - along * outward).norm(), 1e-12);
    if (depth > 0 && out.state == S::IndexContact && out.f_index.isZero(0)) wouldPull = true;
  }
  EXPECT_TRUE(wouldPull) << "the test never reached a pulling damper";
}

TEST(TwoFingerGrasp, DepthRateIsFiltered) {
  // A fingertip held 1 mm deep with +/-10 um of sensor noise at 10 kHz: the contact force
  // trembles far less through the filtered d|p|/dt than through raw differences.
  const auto tremble = [](double cutoff) {
    const Case s;
    GraspParameters k;
    k.rateCutoff_Hz = cutoff;
    TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
    const PartPose pose{s.rotation, s.position};
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> noise(-1e-5, 1e-5);
    HandSample h;
    h.wrist = pose.pointToAbsolute(Vec3(0, -0.1, 0));
    h.thumb = pose.pointToAbsolute(Vec3(-0.08, 0, 0));
    double sum = 0, sum2 = 0;
    int n = 0;
    for (int i = 0; i < 20000; ++i) {
      h.index = pose.pointToAbsolute(Vec3(0.049 + noise(rng), 0, 0));
      const double f = grasp.step(h, i ? 1e-4 : 0).f_index.norm();
      if (i < 2000) continue;
      sum += f;
      sum2 += f * f;
      ++n;
    }
    return std::sqrt(sum2 / n - (sum / n) * (sum / n));
  };
  const double filtered = tremble(100), raw = tremble(kInf);
  EXPECT_LT(filtered, 0.3 * raw) << filtered << " N vs " << raw << " N";
}

// ---------------------------------------------------------------------------------------
// The state sequence, lift, return, release.

TEST(TwoFingerGrasp, PaperSequence) {
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const Trace r = run(grasp, paperScript(s, k));
  ASSERT_EQ(r.states, kStandardSequence) << describe(r.states);
  const std::vector<std::uint32_t> events = {kIndexContact, kIndexDetach, kThumbContact, kIndexContact | kGrasp,
                                             kLift, kRelease};
  EXPECT_EQ(r.transitionEvents, events);
  EXPECT_EQ(r.queriesHolding, 0);  // held parts follow the hand: no penetration query
  expectBounded(r, s, k, "paper sequence");
  // Put down at the new place: turned a quarter about the vertical, moved by the hand.
  const Grip g = gripFor(s, k);
  const Mat3 quarter = Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_LT((r.finalPose.rotation - quarter * s.rotation).norm(), 1e-9);
  const Vec3 expected = s.position + Vec3(0.3, 0.1, 0.5 * (1.5 * g.liftHeight + 0.01));
  EXPECT_LT((r.finalPose.position - expected).norm(), 1e-3);  // the midpoint moved by depth/2 at the grasp
}

TEST(TwoFingerGrasp, WristForceIsContinuousAtLift) {
  for (double dt : {5e-4, 1e-4, 1e-3}) {
    const Case s;
    const GraspParameters k;
    TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
    const Trace r = run(grasp, paperScript(s, k), {.dt = dt});
    ASSERT_GE(r.liftJump, 0) << "no lift";
    const double weight = s.mass_kg * k.gravity.norm();
    // Eq 30 gives exactly the weight; the last GRASP tick gave the spring's pull, which the
    // corrected eq 29 lets reach the weight within one tick of hand motion.
    EXPECT_NEAR(r.verticalAtLift, weight, 1e-12);
    const Grip g = gripFor(s, k);
    const double liftSpeed = (1.5 * g.liftHeight + 0.01) / 0.5;
    EXPECT_LE(r.liftJump, k.K_ox * liftSpeed * dt * 1.001 + 1e-12) << "dt " << dt;
    EXPECT_GT(r.verticalBeforeLift, 0.98 * weight);
    if (dt == 5e-4) {
      EXPECT_LT(r.liftJump, 0.01 * weight);  // 2 kHz: under 1% of the weight
    }
  }
}

TEST(TwoFingerGrasp, PrintedEq29NeverLifts) {
  // f_w . g <= -M|g|^2 asks for a wrist force pushing up, which lifting never gives.
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const Trace r = run(grasp, paperScript(s, k), {}, true);
  const double mg2 = s.mass_kg * k.gravity.squaredNorm();
  bool printedWouldLift = false;
  for (const GraspOutput& out : r.outputs)
    if (out.state == S::Grasp && out.f_wrist.dot(k.gravity) <= -mg2) printedWouldLift = true;
  EXPECT_FALSE(printedWouldLift);
  EXPECT_TRUE(r.events & kLift);
}

TEST(TwoFingerGrasp, ReleaseFromGraspReturnsThePart) {
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const Trace r = run(grasp, paperScript(s, k, Variant::ReturnFromGrasp), {}, true);
  ASSERT_EQ(r.states, kReturnSequence) << describe(r.states);
  EXPECT_EQ(r.transitionEvents.back(), unsigned(kRelease | kReturn));
  EXPECT_EQ(r.finalPose.position, s.position);  // exactly where it was
  EXPECT_EQ(r.finalPose.rotation, s.rotation);
  // While grasped it did move with the hand (the springs pulled it back).
  double maxLift = 0;
  for (std::size_t i = 0; i < r.outputs.size(); ++i)
    if (r.outputs[i].state == S::Grasp) maxLift = std::max(maxLift, r.pose0[i].position.z() - s.position.z());
  EXPECT_GT(maxLift, 0.4 * gripFor(s, k).liftHeight);
}

TEST(TwoFingerGrasp, ReleaseFromManipulateLeavesThePartThere) {
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const Trace r = run(grasp, paperScript(s, k), {}, true);
  const auto release = std::find_if(r.outputs.begin(), r.outputs.end(),
                                    [](const GraspOutput& o) { return o.events & kRelease; });
  ASSERT_NE(release, r.outputs.end());
  EXPECT_FALSE(release->events & kReturn);
  const std::size_t at = release - r.outputs.begin();
  EXPECT_EQ((release - 1)->state, S::Manipulate);
  // Where the last MANIPULATE tick had it, it stays.
  EXPECT_EQ(r.pose0[at].position, r.pose0[at - 1].position);
  EXPECT_EQ(r.pose0[at].rotation, r.pose0[at - 1].rotation);
  EXPECT_EQ(r.finalPose.position, r.pose0[at].position);
  EXPECT_GT((r.finalPose.position - s.position).norm(), 0.2);
  // And it can be touched there: its box moved with it.
  HandSample h;
  h.wrist = r.finalPose.pointToAbsolute(Vec3(0, -0.1, 0));
  h.thumb = r.finalPose.pointToAbsolute(Vec3(-0.08, 0, 0));
  h.index = r.finalPose.pointToAbsolute(Vec3(0.045, 0, 0.1));
  GraspOutput out = grasp.step(h, 5e-4);
  EXPECT_EQ(out.state, S::IndexContact);
  for (int i = 0; i < 400; ++i) out = grasp.step(h, 5e-4);
  EXPECT_NEAR(out.f_index.norm(), 130 * std::sqrt(5e-3), 1e-9);
}

TEST(TwoFingerGrasp, HeldPartFollowsTheHandRigidly) {
  // Eqs 12-22: whatever the hand does after the grasp, the part does with it.
  const Case s;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}));
  const PartPose pose{s.rotation, s.position};
  HandSample h = handIn(pose, Vec3(0.08, 0, 0), Vec3(-0.08, 0, 0), Vec3(0.01, -0.1, 0.02));
  grasp.step(h, 0);
  h.index = pose.pointToAbsolute(Vec3(0.049, 0.003, 0.05));
  grasp.step(h, 1e-3);
  h.thumb = pose.pointToAbsolute(Vec3(-0.0495, -0.002, 0.04));
  const GraspOutput first = grasp.step(h, 1e-3);
  ASSERT_EQ(first.state, S::Grasp);
  const PartPose atGrasp = first.poses[0];
  EXPECT_LT((atGrasp.rotation - pose.rotation).norm(), 1e-14);
  EXPECT_LT((atGrasp.position - pose.position).norm(), 1e-14);
  const HandSample grasped = h;
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 1);
  for (int i = 0; i < 200; ++i) {
    const Mat3 R = math::fromRotationVector(0.8 * Vec3(n(rng), n(rng), n(rng)));
    const Vec3 t = 0.2 * Vec3(n(rng), n(rng), n(rng));
    h.index = R * grasped.index + t;
    h.thumb = R * grasped.thumb + t;
    h.wrist = R * grasped.wrist + t;
    const GraspOutput out = grasp.step(h, 1e-3);
    ASSERT_NE(out.state, S::Free);
    EXPECT_LT((out.poses[0].rotation - R * atGrasp.rotation).norm(), 1e-12);
    EXPECT_LT((out.poses[0].position - (R * atGrasp.position + t)).norm(), 1e-12);
  }
}

TEST(TwoFingerGrasp, SpringsInGraspGravityInManipulate) {
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const Trace r = run(grasp, paperScript(s, k), {}, true);
  const ScenePart& part = grasp.scene().part(0);
  int grasps = 0, manipulates = 0;
  for (std::size_t i = 0; i < r.outputs.size(); ++i) {
    const GraspOutput& out = r.outputs[i];
    const PartPose& pose = r.pose0[i];
    if (out.state == S::Grasp && !(out.events & kGrasp)) {
      ++grasps;
      // Eq 23 against the pose at the transition (the initial one, here).
      EXPECT_LT((out.f_wrist + k.K_ox * (pose.position - s.position)).norm(), 1e-9);
      EXPECT_LT((out.m_wrist + k.K_oe * math::rotationVector(pose.rotation * s.rotation.transpose())).norm(), 1e-9);
    }
    if (out.state == S::Manipulate) {
      ++manipulates;
      EXPECT_LT((out.f_wrist - part.mass.mass_kg * k.gravity).norm(), 1e-12);
    }
    if (out.state == S::Grasp || out.state == S::Manipulate) {
      EXPECT_GT(out.f_grasp, 0);
      EXPECT_NEAR(out.f_index.norm(), out.f_grasp, 1e-9);
      EXPECT_LT((out.f_index + out.f_thumb).norm(), 1e-12);
    }
  }
  EXPECT_GT(grasps, 10);
  EXPECT_GT(manipulates, 100);
}

TEST(TwoFingerGrasp, EccentricGraspMomentIsWeightTimesLeverArm) {
  // Grasped 0.15 m from the centre along the axis, wrist straight above the fingertips.
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const PartPose pose{s.rotation, s.position};
  const double a = 0.15, in = 0.049;
  std::vector<HandKey> keys = {{0.0, {0.07, 0, a}, {-0.07, 0, a}, {0, -0.1, a}},
                               {0.1, {in, 0, a}, {-0.07, 0, a}, {0, -0.1, a}},
                               {0.2, {in, 0, a}, {-in, 0, a}, {0, -0.1, a}},
                               {0.7, {in, 0, a}, {-in, 0, a}, {0, -0.1, a}, Vec3(0, 0, 0.05)},
                               {0.8, {in, 0, a}, {-in, 0, a}, {0, -0.1, a}, Vec3(0, 0, 0.05)}};
  const Trace r = run(grasp, HandScript(keys, pose), {}, true);
  ASSERT_EQ(r.states.back(), S::Manipulate) << describe(r.states);
  const GraspOutput& out = r.outputs.back();
  const double weight = s.mass_kg * k.gravity.norm();
  EXPECT_NEAR(out.m_wrist.norm(), weight * a, 1e-4 * weight * a);
  // About the horizontal axis across the cylinder: the far end pulls down.
  const Vec3 axis = pose.vectorToAbsolute(Vec3::UnitZ());
  EXPECT_NEAR(out.m_wrist.dot(Vec3::UnitZ().cross(axis).normalized()), -weight * a, 1e-3);
}

// ---------------------------------------------------------------------------------------
// Hysteresis.

TEST(TwoFingerGrasp, OscillatingAroundTheReleaseDistanceReleasesOnce) {
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const PartPose pose{s.rotation, s.position};
  HandSample h = handIn(pose, Vec3(0.07, 0, 0), Vec3(-0.049, 0, 0));
  grasp.step(h, 0);
  double gripDistance = 0;
  for (int i = 1; i <= 100; ++i) {
    h.index = pose.pointToAbsolute(Vec3(0.07 - 0.021 * i / 100, 0, 0));
    const GraspOutput out = grasp.step(h, 5e-4);
    if (out.events & kGrasp) gripDistance = (h.index - h.thumb).norm();
  }
  ASSERT_EQ(grasp.state(), S::Grasp);
  // The index swings +/-0.4 mm about the release distance (D) for 2 s.
  int transitions = 0;
  S state = grasp.state();
  for (int i = 0; i < 4000; ++i) {
    const double d = gripDistance + k.d_h + 4e-4 * std::sin(2 * kPi * 5 * i * 5e-4);
    h.index = h.thumb + d * pose.vectorToAbsolute(Vec3::UnitX());
    const GraspOutput out = grasp.step(h, 5e-4);
    transitions += out.state != state;
    state = out.state;
  }
  EXPECT_EQ(transitions, 1);
  EXPECT_EQ(state, S::ThumbContact);  // released; the thumb, 1 mm deep, still touches
}

TEST(TwoFingerGrasp, OscillatingAroundTheGraspDistanceGraspsOnce) {
  // The thumb on the part, the index swinging in and out through the surface (A).
  const Case s;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}));
  const PartPose pose{s.rotation, s.position};
  HandSample h = handIn(pose, Vec3(0.06, 0, 0), Vec3(-0.049, 0, 0));
  grasp.step(h, 0);
  ASSERT_EQ(grasp.state(), S::ThumbContact);
  int transitions = 0;
  S state = grasp.state();
  for (int i = 0; i < 4000; ++i) {
    h.index = pose.pointToAbsolute(Vec3(0.05 + 5e-4 * std::sin(2 * kPi * 5 * i * 5e-4), 0, 0));
    const GraspOutput out = grasp.step(h, 5e-4);
    transitions += out.state != state;
    state = out.state;
  }
  EXPECT_EQ(transitions, 1);
  EXPECT_EQ(state, S::Grasp);
}

TEST(TwoFingerGrasp, TracingAtTheSurfaceDoesNotChatter) {
  // One fingertip trembling +/-50 um about the surface: one contact, no detach.
  const Case s;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}));
  const PartPose pose{s.rotation, s.position};
  HandSample h;
  h.wrist = pose.pointToAbsolute(Vec3(0, -0.1, 0));
  h.thumb = pose.pointToAbsolute(Vec3(-0.09, 0, 0));
  int transitions = 0;
  S state = grasp.state();
  for (int i = 0; i < 4000; ++i) {
    h.index = pose.pointToAbsolute(Vec3(0.05 + 5e-5 * std::sin(2 * kPi * 7 * i * 5e-4), 0, 1e-5 * i));
    const GraspOutput out = grasp.step(h, i ? 5e-4 : 0);
    transitions += out.state != state;
    state = out.state;
  }
  EXPECT_EQ(transitions, 1);
  EXPECT_EQ(state, S::IndexContact);
}

TEST(TwoFingerGrasp, APartReturningOntoTheFingertipsIsNotRegrasped) {
  // Grasp across the diameter, turn the hand a quarter so the fingertips lie along the
  // axis, let go: the part returns to its old orientation, around both fingertips. They
  // feel it, but neither came in from outside, so there is no new grasp until one does.
  const Case s;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}));
  const PartPose pose{s.rotation, s.position};
  HandSample h = handIn(pose, Vec3(0.049, 0, 0), Vec3(-0.049, 0, 0));
  grasp.step(h, 0);  // both come in at once: grasp
  ASSERT_EQ(grasp.state(), S::Grasp);
  const Mat3 quarter = Eigen::AngleAxisd(kPi / 2, pose.vectorToAbsolute(Vec3::UnitY())).toRotationMatrix();
  for (Vec3* x : {&h.index, &h.thumb, &h.wrist}) *x = s.position + quarter * (*x - s.position);
  EXPECT_EQ(grasp.step(h, 1e-3).state, S::Grasp);
  const Vec3 line = (h.index - h.thumb).normalized();
  EXPECT_NEAR(std::abs(line.dot(pose.vectorToAbsolute(Vec3::UnitZ()))), 1.0, 1e-12);
  h.index += 2.5e-3 * line;  // open past d_h: release, the part returns around the fingertips
  const GraspOutput released = grasp.step(h, 1e-3);
  EXPECT_EQ(released.events, unsigned(kRelease | kReturn | kIndexContact | kThumbContact));
  EXPECT_EQ(released.state, S::IndexContact);
  EXPECT_EQ(released.poses[0].rotation, s.rotation);
  EXPECT_GT(released.f_index.norm(), 10);  // 5 cm deep: pushed out
  for (int i = 0; i < 100; ++i) EXPECT_EQ(grasp.step(h, 1e-3).state, S::IndexContact);
  // The index out of the part and back in: now it grasps.
  const Vec3 out = pose.vectorToAbsolute(Vec3(0.08, 0, 0));
  h.index += out;
  EXPECT_EQ(grasp.step(h, 1e-3).state, S::ThumbContact);
  h.index -= out;
  EXPECT_EQ(grasp.step(h, 1e-3).state, S::Grasp);
}

// ---------------------------------------------------------------------------------------
// Degenerate hands and bad samples.

TEST(TwoFingerGrasp, CoincidentFingertipsKeepTheLastFrame) {
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const PartPose pose{s.rotation, s.position};
  HandSample h = handIn(pose, Vec3(0.049, 0, 0), Vec3(-0.049, 0, 0));
  GraspOutput out = grasp.step(h, 0);
  ASSERT_EQ(out.state, S::Grasp);
  const Mat3 rotation = out.poses[0].rotation;
  // Squeeze the fingertips onto one point and hold them there.
  for (int i = 1; i <= 300; ++i) {
    const double u = std::min(1.0, i / 100.0);
    // Together to within a nanometre of sensor noise, whose direction is anything.
    const Vec3 noise = i > 100 ? Vec3(1e-9 * std::sin(i), 1e-9 * std::cos(i), 3e-10) : Vec3::Zero();
    h.index = pose.pointToAbsolute(Vec3(0.049 * (1 - u), 0, 0)) + noise;
    h.thumb = pose.pointToAbsolute(Vec3(-0.049 * (1 - u), 0, 0)) - noise;
    out = grasp.step(h, 1e-3);
    ASSERT_EQ(out.state, S::Grasp);
    ASSERT_TRUE(out.f_index.allFinite() && out.poses[0].rotation.allFinite() && out.poses[0].position.allFinite());
    EXPECT_LT((out.poses[0].rotation - rotation).norm(), 1e-12);
    EXPECT_LT((out.poses[0].position - s.position).norm(), 1e-12);
  }
  EXPECT_LT((h.index - h.thumb).norm(), 3e-9);
  EXPECT_NEAR(out.f_grasp, k.K_g * std::sqrt(0.098 + k.d_h), 1e-3);  // eq 24 (the noise's rate is filtered)
  EXPECT_LT((out.f_index - out.f_grasp * pose.vectorToAbsolute(Vec3::UnitX())).norm(), 1e-9);
}

TEST(TwoFingerGrasp, GraspingWithCoincidentFingertipsUsesTheWrist) {
  // Both fingertips poke into the part at one point on one tick: a grasp with d_bar = 0,
  // its frame from the wrist's axes; opening by d_h releases.
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const PartPose pose{s.rotation, s.position};
  HandSample h;
  h.wrist = pose.pointToAbsolute(Vec3(0, -0.15, 0));
  h.wristRotation = math::fromRotationVector(Vec3(0.1, 0.2, 0.3));
  h.index = h.thumb = pose.pointToAbsolute(Vec3(0, -0.06, 0));
  grasp.step(h, 0);
  h.index = h.thumb = pose.pointToAbsolute(Vec3(0, -0.045, 0));
  GraspOutput out = grasp.step(h, 1e-3);
  ASSERT_EQ(out.state, S::Grasp);
  EXPECT_TRUE(out.f_index.allFinite());
  EXPECT_NEAR(out.f_grasp, k.K_g * std::sqrt(k.d_h), 1e-9);
  EXPECT_LT((out.f_index - out.f_grasp * h.wristRotation.col(0)).norm(), 1e-9);
  EXPECT_LT((out.poses[0].position - s.position).norm(), 1e-12);
  // Move the closed hand up 7 mm (short of the lift): the part follows; then open by d_h,
  // and the part drops back, clear of the fingertips.
  for (int i = 0; i < 70; ++i) {
    h.index += Vec3(0, 0, 1e-4);
    h.thumb += Vec3(0, 0, 1e-4);
    h.wrist += Vec3(0, 0, 1e-4);
    out = grasp.step(h, 1e-3);
    ASSERT_TRUE(out.poses[0].position.allFinite());
  }
  EXPECT_EQ(out.state, S::Grasp);
  EXPECT_NEAR(out.poses[0].position.z() - s.position.z(), 7e-3, 1e-12);
  h.index += 1.1 * k.d_h * Vec3::UnitX();
  out = grasp.step(h, 1e-3);
  EXPECT_EQ(out.state, S::Free);
  EXPECT_EQ(out.events, unsigned(kRelease | kReturn));
}

TEST(TwoFingerGrasp, WristOnTheFingerLineKeepsTheLastFrame) {
  const Case s;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}));
  const PartPose pose{s.rotation, s.position};
  HandSample h = handIn(pose, Vec3(0.049, 0, 0), Vec3(-0.049, 0, 0));
  GraspOutput out = grasp.step(h, 0);
  ASSERT_EQ(out.state, S::Grasp);
  // The wrist slides onto the fingertips' line (beyond the index) and stays there while
  // the fingertips move along the line: the part moves, its orientation holds.
  for (int i = 1; i <= 200; ++i) {
    const double u = std::min(1.0, i / 100.0);
    h.wrist = pose.pointToAbsolute(Vec3(0.15 * u, -0.1 * (1 - u), 0));
    const Vec3 slide = pose.vectorToAbsolute(Vec3(i > 100 ? 1e-4 * (i - 100) : 0, 0, 0));
    h.index = pose.pointToAbsolute(Vec3(0.049, 0, 0)) + slide;
    h.thumb = pose.pointToAbsolute(Vec3(-0.049, 0, 0)) + slide;
    out = grasp.step(h, 1e-3);
    ASSERT_EQ(out.state, S::Grasp);
    ASSERT_TRUE(out.poses[0].rotation.allFinite());
    EXPECT_LT((out.poses[0].rotation - s.rotation).norm(), 1e-9) << i;
  }
  EXPECT_LT((out.poses[0].position - pose.pointToAbsolute(Vec3(0.01, 0, 0))).norm(), 1e-9);
  // Turning the fingertips' line while the wrist stays on it: h1 follows, h2 is the last
  // one made orthogonal -- the part turns with the line, smoothly.
  Mat3 last = out.poses[0].rotation;
  for (int i = 1; i <= 100; ++i) {
    const Mat3 turn = Eigen::AngleAxisd(0.3 * i / 100, pose.vectorToAbsolute(Vec3::UnitZ())).toRotationMatrix();
    const Vec3 c = pose.pointToAbsolute(Vec3(0.01, 0, 0));
    h.index = c + turn * pose.vectorToAbsolute(Vec3(0.049, 0, 0));
    h.thumb = c + turn * pose.vectorToAbsolute(Vec3(-0.049, 0, 0));
    h.wrist = c + turn * pose.vectorToAbsolute(Vec3(0.14, 0, 0));
    out = grasp.step(h, 1e-3);
    ASSERT_TRUE(out.poses[0].rotation.allFinite());
    EXPECT_LT(math::rotationVector(out.poses[0].rotation * last.transpose()).norm(), 0.004);
    last = out.poses[0].rotation;
  }
  EXPECT_NEAR(math::rotationVector(last * s.rotation.transpose()).norm(), 0.3, 1e-9);
}

TEST(TwoFingerGrasp, NaNOrInfSamplesGiveZeroForceAndKeepTheState) {
  const Case s;
  const GraspParameters k;
  TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
  const Trace r = run(grasp, paperScript(s, k), {.invalidEvery = 23});
  EXPECT_EQ(r.states, kStandardSequence) << describe(r.states);
  EXPECT_GT(r.invalidTicks, 100);
  EXPECT_TRUE(r.invalidTicksBehaved);
  expectBounded(r, s, k, "NaN samples");
  // A bad dt is a bad sample too.
  GraspOutput out = grasp.step(HandSample{}, kNaN);
  EXPECT_FALSE(out.validSample);
  out = grasp.step(HandSample{}, -1e-3);
  EXPECT_FALSE(out.validSample);
}

// ---------------------------------------------------------------------------------------
// Sweeps: no NaN, bounded forces, the same state sequence.

TEST(TwoFingerGraspSweep, TimeStep) {
  for (double dt : {1e-5, 1e-4, 5e-4, 1e-3, 5e-3, 1e-2}) {
    for (double jitter : {0.0, 0.5}) {
      const Trace r = runSetup(Case{}, {.dt = dt, .jitter = jitter, .seed = unsigned(dt * 1e6)});
      EXPECT_EQ(r.states, kStandardSequence) << "dt " << dt << " jitter " << jitter << ": " << describe(r.states);
    }
  }
}

TEST(TwoFingerGraspSweep, StiffnessAndDamping) {
  for (double f : {0.01, 0.1, 1.0, 10.0, 100.0}) {
    for (const auto& [stiffness, damping] : {std::pair{f, 1.0}, {1.0, f}, {f, f}}) {
      Case s;
      s.stiffness = stiffness;
      s.damping = damping;
      const Trace r = runSetup(s);
      EXPECT_EQ(r.states, kStandardSequence) << "K x" << stiffness << " B x" << damping << ": " << describe(r.states);
    }
  }
}

TEST(TwoFingerGraspSweep, PartSizeAndMass) {
  // 1 mm to 10 m long (the cylinder scaled), 1 g to 1000 kg.
  for (double length_m : {1e-3, 0.04, 0.4, 10.0}) {
    Case s;
    s.scale = length_m / 0.4;
    s.position = Vec3(0.4, 0, 0.3) * std::max(1.0, s.scale);
    const Trace r = runSetup(s);
    EXPECT_EQ(r.states, kStandardSequence) << length_m << " m: " << describe(r.states);
  }
  for (double mass : {1e-3, 0.1, 2.0, 50.0, 1000.0}) {
    Case s;
    s.mass_kg = mass;
    const Trace r = runSetup(s);
    EXPECT_EQ(r.states, kStandardSequence) << mass << " kg: " << describe(r.states);
    const Trace back = runSetup(s, {}, Variant::ReturnFromGrasp);
    EXPECT_EQ(back.states, kReturnSequence) << mass << " kg: " << describe(back.states);
  }
}

TEST(TwoFingerGraspSweep, Orientations) {
  // Pitch +/-90 degrees (the paper's eq 21 singularity), yaw +/-180, and mixtures, in the
  // paper's RPY; both rotational springs.
  const std::vector<Vec3> rpys = {{0, kPi / 2, 0},   {0, -kPi / 2, 0},     {0, 0, kPi},        {0, 0, -kPi},
                                  {0.3, kPi / 2, kPi}, {-1.0, -kPi / 2, -kPi}, {kPi, 0.4, kPi / 2}, {2.0, -1.0, 3.0}};
  for (const Vec3& rpy : rpys) {
    for (RotationalSpring spring : {RotationalSpring::RotationVector, RotationalSpring::PaperRpy}) {
      Case s;
      s.rotation = math::paperRotation(rpy).transpose();
      GraspParameters k = parametersFor(s);
      k.rotationalSpring = spring;
      TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
      const Trace r = run(grasp, paperScript(s, k));
      EXPECT_EQ(r.states, kStandardSequence) << rpy.transpose() << ": " << describe(r.states);
      expectBounded(r, s, k, "orientation");
      EXPECT_LT((r.finalPose.rotation - Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()).toRotationMatrix() * s.rotation).norm(),
                1e-9);
    }
  }
}

TEST(TwoFingerGraspSweep, DegenerateHands) {
  for (Variant v : {Variant::CoincidentWhileFree, Variant::WristOnFingerLine}) {
    for (double dt : {1e-4, 1e-3}) {
      const Trace r = runSetup(Case{}, {.dt = dt}, v);
      EXPECT_EQ(r.states, kStandardSequence) << int(v) << ": " << describe(r.states);
    }
  }
}

// ---------------------------------------------------------------------------------------
// The servo thread's budget: no allocation; untouched parts cost no query.

TEST(TwoFingerGrasp, StepDoesNotAllocate) {
  for (geometry::Backend backend : {geometry::Backend::Analytic, geometry::Backend::Exact}) {
    Case s;
    s.backend = backend;
    const GraspParameters k;
    TwoFingerGrasp grasp(sceneOf({cylinderFor(s)}), k);
    const HandScript script = paperScript(s, k);
    std::vector<HandSample> samples;
    for (double t = 0; t <= script.duration(); t += 5e-4) samples.push_back(script.at(t));
    samples[500].index.x() = kNaN;
    std::vector<S> states(samples.size());
    const long before = test::allocations();
    for (std::size_t i = 0; i < samples.size(); ++i) states[i] = grasp.step(samples[i], 5e-4).state;
    EXPECT_EQ(test::allocations() - before, 0) << geometry::toString(backend);
    EXPECT_EQ(states.back(), S::Free);
    EXPECT_TRUE(std::find(states.begin(), states.end(), S::Manipulate) != states.end());
  }
}

TEST(TwoFingerGrasp, AllocationCounterSeesAllocations) {
  const long before = test::allocations();
  auto* p = new std::vector<int>(10);
  EXPECT_GT(test::allocations() - before, 0);
  delete p;
}

// Counts the queries that reach a back end.
class CountingPenetration final : public geometry::PenetrationModel {
 public:
  explicit CountingPenetration(geometry::PenetrationModelPtr inner) : inner_(std::move(inner)) {}
  std::string_view name() const noexcept override { return inner_->name(); }
  std::string setting() const override { return inner_->setting(); }
  std::size_t memoryBytes() const noexcept override { return inner_->memoryBytes(); }
  geometry::Penetration query(const Vec3& x, geometry::QueryState& state) const noexcept override {
    ++count;
    return inner_->query(x, state);
  }
  mutable long count = 0;

 protected:
  bool queryFeature(const Vec3& x, geometry::Feature f, int i, double& u, double& v,
                    geometry::Penetration& out) const noexcept override {
    return (inner_.get()->*(&Access::queryFeature))(x, f, i, u, v, out);
  }

 private:
  struct Access : geometry::PenetrationModel {
    using geometry::PenetrationModel::queryFeature;
  };
  geometry::PenetrationModelPtr inner_;
};

TEST(TwoFingerGrasp, OnlyTouchedPartsAreQueried) {
  // The cylinder between a block 0.3 m away and a sphere 1 m away; a box right next to
  // the cylinder, whose box the open fingertips do enter but whose solid they do not.
  const Case s;
  const GraspParameters k;
  std::vector<ScenePart> parts;
  std::vector<std::shared_ptr<CountingPenetration>> counters;
  const auto add = [&](ScenePart part) {
    counters.push_back(std::make_shared<CountingPenetration>(part.penetration));
    part.penetration = counters.back();
    parts.push_back(std::move(part));
  };
  add(makeScenePart(test::boxPart(), MassSpec::density(2700), PartPose{Mat3::Identity(), Vec3(0.4, 0.35, 0.3)}));
  add(cylinderFor(s));
  add(makeScenePart(test::spherePart(), MassSpec::density(1000), PartPose{Mat3::Identity(), Vec3(-0.6, 0, 0.3)}));
  // A thin plate 1 cm beyond the open thumb: its box, inflated, still misses the thumb.
  add(makeScenePart(test::boxPart(10, 300, 100), MassSpec::density(1000),
                    PartPose{Mat3::Identity(), Vec3(0.4 - 0.05 - 0.02 - 0.01 - 0.005, 0, 0.3)}));
  TwoFingerGrasp grasp(sceneOf(std::move(parts)), k);
  const Trace r = run(grasp, paperScript(s, k));
  EXPECT_EQ(r.states, kStandardSequence) << describe(r.states);
  EXPECT_EQ(counters[0]->count, 0);
  EXPECT_EQ(counters[2]->count, 0);
  EXPECT_EQ(counters[3]->count, 0);
  EXPECT_GT(counters[1]->count, 100);
  EXPECT_EQ(r.queries, counters[1]->count);  // GraspOutput::queries counts the same
  EXPECT_EQ(r.queriesHolding, 0);
  EXPECT_EQ(grasp.poses()[0].position, Vec3(0.4, 0.35, 0.3));
  EXPECT_GT((grasp.poses()[1].position - s.position).norm(), 0.2);  // the cylinder was moved
}

TEST(TwoFingerGrasp, RejectsBadConstruction) {
  EXPECT_THROW(TwoFingerGrasp(nullptr), std::invalid_argument);
  GraspParameters k;
  k.K_c = -1;
  EXPECT_THROW(TwoFingerGrasp(sceneOf({cylinderFor(Case{})}), k), std::invalid_argument);
  ScenePart bad = cylinderFor(Case{});
  bad.initialPose.rotation(0, 0) = 2;
  EXPECT_THROW(Scene({bad}), std::invalid_argument);
  bad = cylinderFor(Case{});
  bad.penetration = geometry::makeReferencePenetration(bad.model);  // allocates: not for the servo thread
  EXPECT_THROW(Scene({bad}), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------
// The experiment of section 5.

TEST(GraspCylinderExperiment, Fig6) {
  const GraspCylinderResult r = runGraspCylinder(2000);
  std::vector<S> sequence = {S::Free};
  for (const GraspCylinderTransition& t : r.transitions) {
    EXPECT_EQ(t.from, sequence.back());
    sequence.push_back(t.to);
  }
  const std::vector<S> expected = {S::Free,  S::IndexContact, S::Free,       S::ThumbContact,
                                   S::Grasp, S::Manipulate,   S::Free,       S::IndexContact,
                                   S::Grasp, S::Manipulate,   S::Free};
  EXPECT_EQ(sequence, expected) << describe(sequence);
  EXPECT_NEAR(r.weight_N, 2 * 9.80665, 1e-9);
  EXPECT_GT(r.force_jump_at_lift_N, 0);
  EXPECT_LT(r.force_jump_at_lift_N, 0.01 * r.weight_N);
  EXPECT_NEAR(r.eccentric_moment_Nm, r.expected_eccentric_moment_Nm, 1e-3 * r.expected_eccentric_moment_Nm);
  EXPECT_NEAR(r.expected_eccentric_moment_Nm, r.weight_N * 0.15, 1e-12);
  EXPECT_GT(r.max_force_N, r.weight_N);
  EXPECT_GT((r.finalPose.position - r.initialPose.position).norm(), 0.25);
  const Mat3 quarter = Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_LT((r.finalPose.rotation - quarter * r.initialPose.rotation).norm(), 1e-9);

  const nlohmann::json j = nlohmann::json::parse(toJson(r));
  for (const char* field : {"transitions", "weight_N", "force_jump_at_lift_N", "max_force_N", "initial_pose",
                            "final_pose", "eccentric_moment_Nm", "expected_eccentric_moment_Nm"})
    EXPECT_TRUE(j.contains(field)) << field;
  EXPECT_EQ(j["transitions"].size(), r.transitions.size());
  EXPECT_EQ(j["transitions"][3]["from"], "THUMB CONTACT");
  EXPECT_EQ(j["transitions"][3]["to"], "GRASP");
  EXPECT_EQ(j["final_pose"]["rpy_rad"].size(), 3u);
  std::printf("%s\n", runGraspCylinderExperiment().c_str());
}

}  // namespace
}  // namespace hg::grasp
