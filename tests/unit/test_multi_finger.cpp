// The resultant-force paper's grasp models: 1 DOF (section 4) and its experiment (section 6).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>
#include <nlohmann/json.hpp>

#include "alloc_counter.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/grasp/multi_finger/god_object.hpp"
#include "hapticgrasp/grasp/multi_finger/multi_finger_grasp.hpp"
#include "hapticgrasp/grasp/multi_finger/shape_shell.hpp"
#include "hapticgrasp/grasp/multi_finger/one_dof.hpp"
#include "hapticgrasp/grasp/shake_experiment.hpp"
#include "hapticgrasp/math/rpy.hpp"
#include "test_shapes.hpp"

using namespace hg::grasp;
using namespace hg::grasp::multi_finger;

namespace {

// The fingers of a hand shaking a held block: wrist sine, fixed aperture.
struct Hand {
  double aperture, amplitude, frequency;
  double thumb(double t) const { return wrist(t) - 0.5 * aperture; }
  double index(double t) const { return wrist(t) + 0.5 * aperture; }
  double wrist(double t) const { return amplitude * std::sin(2 * M_PI * frequency * t); }
};

}  // namespace

// Eq 12: with the shell, the grasping force is k_g (l − gap)/2 whatever the resultant; the
// conventional springs obey eq 8 instead (gap = l − (2 f_g + |f_r|)/k).
TEST(OneDof, Eq12GraspForceFollowsTheGapOnlyEq8Conventional) {
  OneDofParams p;
  p.dampingRatio = 0;  // eq 8 holds for the bare springs
  ConventionalOneDof conv(p);
  ProposedOneDof prop(p);
  conv.reset(0);
  prop.reset(0);
  const Hand hand{0.055, 0.03, 2.0};
  const double dt = 1e-3;
  double maxResultantConv = 0, maxResultantProp = 0;
  for (int i = 0; i < 4000; ++i) {
    const double t = i * dt;
    const OneDofOutput& c = conv.step(hand.thumb(t), hand.index(t), 0, dt);
    if (c.grasped) {
      EXPECT_NEAR(c.distance, p.length - (2 * c.graspForce + std::abs(c.resultant)) / p.kGrasp, 1e-9) << t;
    }
    maxResultantConv = std::max(maxResultantConv, std::abs(c.resultant));
    const OneDofOutput& o = prop.step(hand.thumb(t), hand.index(t), 0, dt);
    ASSERT_TRUE(o.grasped);
    EXPECT_NEAR(o.graspForce, p.kGrasp * (p.length - o.distance) / 2, 1e-9) << t;
    EXPECT_NEAR(o.distance, p.length - 2 * o.graspForce / p.kGrasp, 1e-12) << t;  // eq 12
    maxResultantProp = std::max(maxResultantProp, std::abs(o.resultant));
  }
  EXPECT_GT(maxResultantConv, 1.0);  // the shake really needed a resultant
  EXPECT_GT(maxResultantProp, 1.0);
}

// Section 4.3: the resultant never lowers a finger's grasping force, and the fingers give
// the part what its motion needs (m ẍ = f_r + f_e).
TEST(OneDof, DistributionNeverLowersGraspingForceAndMatchesResultant) {
  OneDofParams p;
  ProposedOneDof prop(p);
  prop.reset(0);
  const Hand hand{0.054, 0.04, 2.5};
  const double dt = 5e-4;
  double lastV = 0;
  for (int i = 0; i < 6000; ++i) {
    const double t = i * dt;
    const double fe = 0.5 * std::sin(3 * t);  // some external force along the grasp
    const OneDofOutput& o = prop.step(hand.thumb(t), hand.index(t), fe, dt);
    const double fg = p.kGrasp * (p.length - o.distance) / 2;
    EXPECT_GE(-o.thumbForce, fg - 1e-9);
    EXPECT_GE(o.indexForce, fg - 1e-9);
    EXPECT_NEAR(o.graspForce, fg, 1e-9);
    // Exactly one finger carries the resultant.
    EXPECT_TRUE(std::abs(-o.thumbForce - fg) < 1e-9 || std::abs(o.indexForce - fg) < 1e-9);
    EXPECT_NEAR(p.mass * (o.partVelocity - lastV) / dt, o.resultant + fe, 1e-6 * (1 + std::abs(o.resultant)));
    lastV = o.partVelocity;
  }
}

TEST(OneDof, StepIsAllocationFreeAndIgnoresNonFiniteInput) {
  ConventionalOneDof conv;
  ProposedOneDof prop;
  conv.reset(0);
  prop.reset(0);
  const long before = hg::test::allocations();
  for (int i = 0; i < 1000; ++i) {
    conv.step(-0.028, 0.028, 0.1, 1e-3);
    prop.step(-0.028, 0.028, 0.1, 1e-3);
  }
  EXPECT_EQ(hg::test::allocations(), before);
  const double x = prop.output().partPosition;
  prop.step(NAN, 0.028, 0, 1e-3);
  prop.step(-0.028, 0.028, 0, 0.0);
  conv.step(-0.028, INFINITY, 0, 1e-3);
  EXPECT_EQ(prop.output().partPosition, x);
  EXPECT_TRUE(std::isfinite(conv.output().partPosition));
}

// A single finger pushes the part: the shell moves with it, the part follows through k_d.
TEST(OneDof, ProposedPushWithOneFinger) {
  ProposedOneDof prop;
  prop.reset(0);
  double thumb = -0.05;
  for (int i = 0; i < 3000; ++i) {
    thumb += 0.1 * 1e-3;  // 0.1 m/s towards +x
    const OneDofOutput& o = prop.step(thumb, 1.0, 0, 1e-3);
    EXPECT_LE(o.thumbForce, 0);
    EXPECT_EQ(o.indexForce, 0);
  }
  EXPECT_GT(prop.output().partPosition, 0.2);
  EXPECT_NEAR(prop.output().partVelocity, 0.1, 0.02);
}

// Eq 12 in the experiment: the proposed method's finger distance does not depend on the
// resultant (two shake amplitudes give the same distance); the conventional one shrinks
// with the resultant (eq 8).
TEST(ShakeExperiment, Eq12DistanceIndependentOfShakeAmplitude) {
  ShakeConfig a, b;
  a.duration = b.duration = 12;
  a.handStiffness = b.handStiffness = 0;  // a rigid hand: the fingers are where the subject puts them
  a.amplitude = 0.02;
  b.amplitude = 0.04;
  const ShakeResult ra = runShakeExperiment(a), rb = runShakeExperiment(b);
  EXPECT_GT(rb.proposed.resultant_max_N, 1.5 * ra.proposed.resultant_max_N);
  EXPECT_NEAR(ra.proposed.distance_mean_m, rb.proposed.distance_mean_m, 1e-4);
  EXPECT_NEAR(ra.proposed.distance_std_m, rb.proposed.distance_std_m, 1e-4);
  EXPECT_LT(rb.conventional.distance_mean_m, ra.conventional.distance_mean_m - 5e-4);
  EXPECT_GT(rb.conventional.distance_std_m, ra.conventional.distance_std_m);
  // A compliant hand gives way to the resultant: the proposed distance grows a little
  // (the paper's section 6.2 observation), but far less than the conventional one shrinks.
  a.handStiffness = b.handStiffness = 2000;
  const ShakeResult ca = runShakeExperiment(a), cb = runShakeExperiment(b);
  EXPECT_LT(std::abs(cb.proposed.distance_mean_m - ca.proposed.distance_mean_m),
            0.25 * std::abs(cb.conventional.distance_mean_m - ca.conventional.distance_mean_m));
}

// Tables 1–2's direction: the proposed method's distance and grasping force vary less.
TEST(ShakeExperiment, ProposedIsSteadierThanConventional) {
  const ShakeResult r = runShakeExperiment();
  EXPECT_TRUE(r.conventional.finite);
  EXPECT_TRUE(r.proposed.finite);
  EXPECT_LT(r.proposed.distance_std_m, r.conventional.distance_std_m);
  EXPECT_LT(r.proposed.grasp_force_std_N, r.conventional.grasp_force_std_N);
  EXPECT_GT(r.proposed.distance_mean_m, r.conventional.distance_mean_m);
  // The subject holds about its target (2 N, as Table 1's subjects).
  EXPECT_NEAR(r.proposed.grasp_force_mean_N, r.target_grasp_force_N, 0.2 * r.target_grasp_force_N);
  const auto j = nlohmann::json::parse(toJson(r));
  for (const char* m : {"conventional", "proposed"})
    for (const char* f : {"grasp_force_mean_N", "grasp_force_std_N", "distance_mean_m", "distance_std_m"})
      EXPECT_TRUE(j["methods"][m][f].is_number()) << m << " " << f;
  const std::string svg = toSvg(r);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
}

// Extremes: dt 1e-4..1e-2, stiffness x0.01..x100, tiny and heavy parts: no NaN, bounded.
TEST(ShakeExperiment, ExtremesStayFiniteAndBounded) {
  for (double dt : {1e-4, 3e-4, 1e-3, 3e-3, 1e-2}) {
    for (double scale : {0.01, 0.1, 1.0, 10.0, 100.0}) {
      for (double mass : {0.01, 1.0, 50.0}) {
        ShakeConfig c;
        c.dt = dt;
        c.duration = dt < 5e-4 ? 3 : 8;
        c.stiffness = 800 * scale;
        c.dynamicsStiffness = 800 * scale;
        c.mass = mass;
        const ShakeResult r = runShakeExperiment(c);
        for (const ShakeMethodResult* m : {&r.conventional, &r.proposed}) {
          SCOPED_TRACE(testing::Message() << "dt " << dt << " stiffness x" << scale << " mass " << mass);
          EXPECT_TRUE(m->finite);
          // Bounded: no force beyond what the springs can give over the part's width
          // plus the part's inertia at the shake (with a generous factor).
          const double inertia = mass * c.amplitude * std::pow(2 * M_PI * c.frequency, 2);
          EXPECT_LT(m->max_force_N, 10 * (c.stiffness * c.width + inertia) + 10);
          EXPECT_GT(m->distance_mean_m, 0);
          EXPECT_LT(m->distance_mean_m, 2.01 * c.width);
        }
      }
    }
  }
}

TEST(ShakeExperiment, RejectsBadConfig) {
  ShakeConfig c;
  c.dt = 0;
  EXPECT_THROW(runShakeExperiment(c), std::invalid_argument);
  c = {};
  c.stiffness = NAN;
  EXPECT_THROW(runShakeExperiment(c), std::invalid_argument);
}

// The god object never passes through a 2 mm plate pushed hard from +z to z = −10 mm: the
// force stays along +z and grows monotonically. The raw closest point flips to the far
// face past the middle (its force would point −z), then lets go.
TEST(GodObject, ThinPlatePushedHardNeverPassesThrough) {
  const auto plate = hg::geometry::makeExactPenetration(hg::test::boxPart(100, 100, 2));
  GodObjectParams params;
  params.stiffness = 800;
  GodObject proxy(*plate, params);
  hg::geometry::QueryState raw;
  double lastForce = 0;
  bool rawFlipped = false, touched = false;
  for (int i = 0; i <= 150; ++i) {
    const hg::Vec3 x(0.010, 0.005, 0.005 - i * 1e-4);  // 5 mm above to 10 mm below the middle
    const GodObjectContact& c = proxy.update(x);
    if (x.z() < 0.001) {
      ASSERT_TRUE(c.inContact) << x.z();
      touched = true;
      EXPECT_NEAR(c.proxy.z(), 0.001, 1e-9);
      EXPECT_NEAR(c.force.x(), 0, 1e-9);
      EXPECT_NEAR(c.force.y(), 0, 1e-9);
      EXPECT_GT(c.force.z(), 0);
      EXPECT_GE(c.force.z(), lastForce - 1e-12);
      EXPECT_NEAR(c.force.z(), params.stiffness * (0.001 - x.z()), 1e-9);
      lastForce = c.force.z();
    } else {
      EXPECT_FALSE(c.inContact);
    }
    const hg::geometry::Penetration p = plate->query(x, raw);
    if (p.inside && p.normal.z() < -0.5) rawFlipped = true;  // the closest point's force: −z
  }
  EXPECT_TRUE(touched);
  EXPECT_TRUE(rawFlipped);
  EXPECT_NEAR(lastForce, 800 * 0.011, 1e-9);
  // Pulled back out: released.
  EXPECT_FALSE(proxy.update(hg::Vec3(0.010, 0.005, 0.002)).inContact);
}

// Coulomb friction: stick within μ F_n, slide along the cone's edge beyond.
TEST(GodObject, CoulombFrictionSticksThenSlides) {
  const auto box = hg::geometry::makeExactPenetration(hg::test::boxPart());  // top face z = 15 mm
  GodObjectParams params;
  params.stiffness = 800;
  params.friction = 1.0;
  GodObject proxy(*box, params);
  ASSERT_TRUE(proxy.update(hg::Vec3(0, 0, 0.014)).inContact);  // 1 mm deep: F_n = 0.8 N
  const GodObjectContact& stick = proxy.update(hg::Vec3(0.0005, 0, 0.014));
  EXPECT_FALSE(stick.sliding);
  EXPECT_NEAR(stick.proxy.x(), 0, 1e-9);
  EXPECT_NEAR(stick.force.x(), -0.4, 1e-9);
  EXPECT_NEAR(stick.normalForce, 0.8, 1e-9);
  const GodObjectContact& slide = proxy.update(hg::Vec3(0.003, 0, 0.014));
  EXPECT_TRUE(slide.sliding);
  EXPECT_NEAR(slide.tangentialForce, 0.8, 1e-9);
  EXPECT_NEAR(slide.proxy.x(), 0.002, 1e-9);
  EXPECT_NEAR(slide.proxy.z(), 0.015, 1e-9);
  // Frictionless: the proxy is the foot.
  params.friction = 0;
  proxy.setParams(params);
  EXPECT_NEAR(proxy.update(hg::Vec3(0.004, 0, 0.014)).tangentialForce, 0, 1e-9);
}

TEST(GodObject, UpdateIsAllocationFreeOnTheExactBackEnd) {
  const auto plate = hg::geometry::makeExactPenetration(hg::test::boxPart(100, 100, 2));
  GodObject proxy(*plate);
  proxy.update(hg::Vec3(0.01, 0.005, 0.002));
  proxy.update(hg::Vec3(0.01, 0.005, 0.0005));
  const long before = hg::test::allocations();
  for (int i = 0; i < 200; ++i) proxy.update(hg::Vec3(0.01 + 1e-5 * i, 0.005, 0.0005 - 5e-5 * i));
  EXPECT_EQ(hg::test::allocations(), before);
  EXPECT_TRUE(proxy.contact().inContact);
  proxy.update(hg::Vec3(NAN, 0, 0));
  EXPECT_TRUE(proxy.contact().force.allFinite());
}

// Eqs 15–18: the balanced shell leaves no net force and no net torque on it.
TEST(ShapeShell, BalanceLeavesNoForceNoTorque) {
  const std::vector<hg::Vec3> fingers{{0.028, 0.001, 0.002}, {-0.027, -0.002, 0.0}, {0.0, 0.031, -0.001}};
  const std::vector<hg::Vec3> proxies{{0.03, 0.0, 0.0}, {-0.03, 0.0, 0.0}, {0.0, 0.03, 0.0}};
  const ShellBalance b = balanceShell(fingers, proxies);
  ASSERT_TRUE(b.valid);
  hg::Vec3 f = hg::Vec3::Zero(), t = hg::Vec3::Zero();
  for (std::size_t i = 0; i < fingers.size(); ++i) {
    const hg::Vec3 r = b.centre + b.rotation * (proxies[i] - b.centre) + b.translation;
    f += fingers[i] - r;
    t += (r - b.centre).cross(fingers[i] - r);
  }
  EXPECT_LT(f.norm(), 1e-9);
  EXPECT_LT(t.norm(), 1e-10);
  // Two fingers: the spin about their line is left alone (no NaN, no motion).
  const ShellBalance two = balanceShell(std::span(fingers.data(), 2), std::span(proxies.data(), 2));
  EXPECT_TRUE(two.translation.allFinite());
  EXPECT_TRUE(two.rotation.allFinite());
}

namespace {

struct Block {
  hg::geometry::PartModelPtr part;
  hg::geometry::PenetrationModelPtr model;
  hg::geometry::MassProperties mass;
};
Block block(double x_mm, double y_mm, double z_mm, double kg) {
  Block b;
  b.part = hg::test::boxPart(x_mm, y_mm, z_mm);
  b.model = hg::geometry::makeExactPenetration(b.part);
  b.mass = b.part->massProperties(hg::geometry::MassSpec::mass(kg));
  return b;
}

}  // namespace

// The paper's block held by thumb and index on its 6 cm faces under g = 2 m/s²: the weight
// is held by friction, the grasping forces are equal and opposite (the balanced shell),
// a small twist about the grasp axis is held by torsional friction and a large one slips.
TEST(MultiFingerGrasp, TwoFingersHoldTheBlockAndResistSpinning) {
  const Block b = block(60, 60, 100, 1.0);
  MultiFingerParams params;
  params.gravity = hg::Vec3(0, 0, -2.0);
  params.torsionalFriction = 0.005;
  MultiFingerGrasp grasp(b.model, b.mass, 2, params);
  const std::vector<hg::Vec3> tips{{0.0275, 0, 0}, {-0.0275, 0, 0}};
  const double dt = 1e-3;
  auto run = [&](const hg::Vec3& torque, int ticks) {
    for (int i = 0; i < ticks; ++i) grasp.step(tips, hg::Vec3::Zero(), torque, dt);
    return grasp.output();
  };
  const MultiFingerOutput held = run(hg::Vec3::Zero(), 2000);
  EXPECT_EQ(held.contacts, 2);
  EXPECT_NEAR(held.fingers[0].graspForce, held.fingers[1].graspForce, 1e-6);
  EXPECT_NEAR(held.fingers[0].force.x(), 2.0, 0.1);   // k · 2.5 mm, pushed out +x
  EXPECT_NEAR(held.fingers[1].force.x(), -2.0, 0.1);
  EXPECT_NEAR(held.fingers[0].force.z() + held.fingers[1].force.z(), -2.0, 0.05);  // the weight, felt
  EXPECT_GT(held.body.position.z(), -0.01);  // hangs by its spring, not dropped
  EXPECT_FALSE(held.slipping);
  // Small twist about the grasp axis: held (limit μ_t · 2 N per finger = 0.02 N m total).
  const MultiFingerOutput twisted = run(hg::Vec3(0.01, 0, 0), 2000);
  EXPECT_FALSE(twisted.slipping);
  EXPECT_LT(hg::math::rotationVector(twisted.body.rotation).norm(), 0.1);
  // Large twist: slips round.
  const MultiFingerOutput spun = run(hg::Vec3(0.2, 0, 0), 2000);
  EXPECT_TRUE(spun.slipping);
  EXPECT_GT(hg::math::rotationVector(spun.body.rotation).norm(), 0.3);
  for (const auto& f : spun.fingers) EXPECT_TRUE(f.force.allFinite());
}

// Extremes: five fingers pushing one face, fingers on opposite edges, tiny and heavy parts,
// dt 1e-4..1e-2: never NaN, forces bounded.
TEST(MultiFingerGrasp, ExtremesStayFiniteAndBounded) {
  struct Case {
    const char* name;
    double size_mm, kg;
    std::vector<hg::Vec3> tips;  // in units of the half size
  };
  const std::vector<Case> cases{
      {"five on one face", 60, 1.0,
       {{0, 0, 0.95}, {0.5, 0, 0.95}, {-0.5, 0, 0.95}, {0, 0.5, 0.95}, {0, -0.5, 0.95}}},
      {"opposite edges", 60, 1.0, {{0.97, 0, 0.97}, {-0.97, 0, -0.97}}},
      {"three round", 60, 1.0, {{0.95, 0, 0}, {-0.6, 0.95, 0}, {-0.6, -0.95, 0}}},
      {"tiny", 2, 1e-4, {{0.9, 0, 0}, {-0.9, 0, 0}}},
      {"heavy", 300, 200.0, {{0.99, 0, 0}, {-0.99, 0, 0}, {0, 0.99, 0.5}}},
  };
  for (const Case& c : cases) {
    const Block b = block(c.size_mm, c.size_mm, c.size_mm, c.kg);
    const double half = 0.5e-3 * c.size_mm;
    for (double dt : {1e-4, 1e-3, 1e-2}) {
      for (double kScale : {0.01, 1.0, 100.0}) {
        SCOPED_TRACE(testing::Message() << c.name << " dt " << dt << " stiffness x" << kScale);
        MultiFingerParams params;
        params.stiffness = 800 * kScale;
        params.dynamicsStiffness = 800 * kScale;
        MultiFingerGrasp grasp(b.model, b.mass, static_cast<int>(c.tips.size()), params);
        std::vector<hg::Vec3> tips(c.tips.size());
        const int ticks = static_cast<int>(0.5 / dt);
        double largest = 0;
        for (int i = 0; i < ticks; ++i) {
          const double t = i * dt;
          for (std::size_t j = 0; j < tips.size(); ++j)  // squeeze in and wobble
            tips[j] = c.tips[j] * half * (1 - 0.02 * std::sin(6 * t)) + hg::Vec3(0.2 * half * std::sin(9 * t), 0, 0);
          const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
          ASSERT_TRUE(o.body.position.allFinite());
          ASSERT_TRUE(o.body.rotation.allFinite());
          for (const FingerOutput& f : o.fingers) {
            ASSERT_TRUE(f.force.allFinite());
            ASSERT_TRUE(f.torsion.allFinite());
            largest = std::max(largest, f.force.norm());
          }
        }
        // Bounded: the springs over the part's size plus its weight and shake, generously.
        const double bound = 10 * (params.stiffness * 2 * half + c.kg * 9.81 * 5) + 1;
        EXPECT_LT(largest, bound);
        EXPECT_LT(grasp.output().body.position.norm(), 100.0);
      }
    }
  }
}

TEST(MultiFingerGrasp, StepIsAllocationFree) {
  const Block b = block(60, 60, 100, 1.0);
  MultiFingerGrasp grasp(b.model, b.mass, 3);
  const std::vector<hg::Vec3> tips{{0.0275, 0, 0}, {-0.0275, 0.01, 0}, {-0.0275, -0.01, 0}};
  for (int i = 0; i < 20; ++i) grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), 1e-3);
  const long before = hg::test::allocations();
  for (int i = 0; i < 500; ++i) grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), 1e-3);
  EXPECT_EQ(hg::test::allocations(), before);
  EXPECT_EQ(grasp.output().contacts, 3);
}

namespace {

// The paper's experiment (section 6) in 6 DOF: two fingers hold the 6 cm × 6 cm × 10 cm
// block on its 6 cm faces under g = 2 m/s²; the wrist shakes it sideways (along the grasp)
// while a simulated subject keeps the grasping force (eq 2: the smaller normal force) at
// its target by opening or closing the fingers. Returns the std of the finger distance.
struct SixDofShake {
  double distanceMean = 0, distanceStd = 0, resultantMax = 0;
  bool finite = true, held = true;
};
SixDofShake shake6(Method method, double dt = 1e-3) {
  const Block b = block(60, 60, 100, 1.0);
  MultiFingerParams params;
  params.method = method;
  params.gravity = hg::Vec3(0, 0, -2.0);
  MultiFingerGrasp grasp(b.model, b.mass, 2, params);
  // The target grip: three times the weight's share over the friction (2 N would let the
  // conventional grasp slip out when the resultant dips its grasping force, eq 8).
  const double target = 3.0, tau = 0.2, amplitude = 0.03, frequency = 1.5;
  double aperture = 0.054;  // 2.4 N: the subject settles to its target in the first second
  std::vector<hg::Vec3> tips(2);
  SixDofShake r;
  double sum = 0, sum2 = 0;
  int samples = 0;
  const int ticks = static_cast<int>(8.0 / dt);
  for (int i = 0; i < ticks; ++i) {
    const double t = i * dt;
    const double wrist = amplitude * (1 - std::cos(2 * M_PI * frequency * t));
    tips[0] = hg::Vec3(wrist + 0.5 * aperture, 0, 0);
    tips[1] = hg::Vec3(wrist - 0.5 * aperture, 0, 0);
    const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
    double fg = o.contacts == 2 ? INFINITY : 0.0;
    for (int j = 0; j < 2; ++j) {
      const FingerOutput& f = o.fingers[j];
      if (!f.force.allFinite() || !o.body.position.allFinite()) r.finite = false;
      if (f.contact) fg = std::min(fg, std::max(0.0, f.force.dot(f.normal)));
    }
    if (o.contacts != 2) r.held = false;
    aperture += dt / tau * (2.0 / params.stiffness) * (fg - target);
    aperture = std::clamp(aperture, 0.006, 0.12);
    if (t >= 1.0) {
      sum += aperture;
      sum2 += aperture * aperture;
      ++samples;
      r.resultantMax = std::max(r.resultantMax, o.resultantForce.head<2>().norm());
    }
  }
  r.distanceMean = sum / samples;
  r.distanceStd = std::sqrt(std::max(0.0, sum2 / samples - r.distanceMean * r.distanceMean));
  return r;
}

}  // namespace

// Eq 8 against eq 12 in 6 DOF: the conventional springs carry the resultant, so the finger
// distance the subject needs for its grasping force swings with the shake; the proposed
// shell keeps it (the resultant goes round the springs).
TEST(MultiFingerGrasp, ConventionalDistanceFollowsTheResultantProposedDoesNot) {
  const SixDofShake conv = shake6(Method::Conventional);
  const SixDofShake prop = shake6(Method::Proposed);
  std::printf("6-DOF shake: distance std conventional %.4g mm, proposed %.4g mm; mean %.4g / %.4g mm; "
              "max |F_xy| %.3g / %.3g N\n",
              1e3 * conv.distanceStd, 1e3 * prop.distanceStd, 1e3 * conv.distanceMean, 1e3 * prop.distanceMean,
              conv.resultantMax, prop.resultantMax);
  ASSERT_TRUE(conv.finite);
  ASSERT_TRUE(prop.finite);
  EXPECT_TRUE(conv.held);  // both grasps keep the block between the fingers
  EXPECT_TRUE(prop.held);
  EXPECT_GT(conv.resultantMax, 1.0);  // the shake really needed a resultant
  EXPECT_GT(prop.resultantMax, 1.0);
  EXPECT_GT(conv.distanceStd, 5 * prop.distanceStd);
  // Eq 8: |f_r| / k of 800 N/m is millimetres; eq 12 leaves the distance at l − 2 f_g / k.
  EXPECT_GT(conv.distanceStd, 1e-4);
  EXPECT_LT(prop.distanceStd, 2e-5);
  EXPECT_NEAR(prop.distanceMean, 0.06 - 2 * 3.0 / 800, 5e-4);
  EXPECT_LT(conv.distanceMean, prop.distanceMean);
}

// The conventional fingers feel exactly their springs, and the part moves by them alone:
// m Δv = dt (Σ f_i + m g), f_i the springs' forces on the part.
TEST(MultiFingerGrasp, ConventionalFingersFeelTheirSpringsOnTheBody) {
  const Block b = block(60, 60, 100, 1.0);
  MultiFingerParams params;
  params.method = Method::Conventional;
  params.gravity = hg::Vec3(0, 0, -2.0);
  MultiFingerGrasp grasp(b.model, b.mass, 3, params);
  const double dt = 1e-3;
  std::vector<hg::Vec3> tips{{0.0275, 0, 0}, {-0.0275, 0.01, 0}, {-0.0275, -0.01, 0.01}};
  hg::Vec3 lastV = grasp.body().velocity();
  for (int i = 0; i < 2000; ++i) {
    const double t = i * dt;
    for (auto& p : tips) p.y() += 0.02 * dt * std::cos(3 * t);
    const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
    hg::Vec3 onPart = hg::Vec3::Zero();
    for (int j = 0; j < 3; ++j) {
      const FingerOutput& f = o.fingers[j];
      if (!f.contact) continue;
      EXPECT_NEAR((f.force - params.stiffness * (f.proxy - tips[j])).norm(), 0, 1e-3 * (1 + f.force.norm()));
      EXPECT_EQ(f.share, 0);
      EXPECT_TRUE(f.torsion.isZero());
      onPart -= f.force;
    }
    EXPECT_LT((o.resultantForce - onPart).norm(), 1e-9);
    const hg::Vec3 v = grasp.body().velocity();
    EXPECT_LT((b.mass.mass_kg * (v - lastV) / dt - onPart - b.mass.mass_kg * params.gravity).norm(), 1e-6);
    EXPECT_EQ(o.body.position, o.shell.position);
    lastV = v;
  }
  EXPECT_EQ(grasp.output().contacts, 3);
  EXPECT_GT(grasp.output().body.position.z(), -0.02);  // held up by friction at the god objects
}

// Both methods, 2–5 fingers, dt 1e-4..1e-2 and stiffness ×0.01..×100: no NaN, bounded.
TEST(MultiFingerGrasp, BothMethodsStayFiniteAndBoundedOverDtAndFingers) {
  const std::vector<std::vector<hg::Vec3>> hands{
      {{0.95, 0, 0}, {-0.95, 0, 0}},
      {{0.95, 0, 0}, {-0.6, 0.95, 0}, {-0.6, -0.95, 0}},
      {{0.95, 0, 0}, {-0.95, 0, 0}, {0, 0.95, 0}, {0, -0.95, 0}},
      {{-0.95, 0, 0}, {0.95, 0.5, 0.3}, {0.95, -0.5, 0.3}, {0.95, 0.5, -0.3}, {0.95, -0.5, -0.3}},
  };
  const Block b = block(60, 60, 60, 1.0);
  const double half = 0.03;
  for (Method method : {Method::Conventional, Method::Proposed}) {
    for (const auto& hand : hands) {
      for (double dt : {1e-4, 1e-3, 3e-3, 1e-2}) {
        for (double kScale : {0.01, 1.0, 100.0}) {
          SCOPED_TRACE(testing::Message() << (method == Method::Conventional ? "conventional " : "proposed ")
                                          << hand.size() << " fingers dt " << dt << " stiffness x" << kScale);
          MultiFingerParams params;
          params.method = method;
          params.stiffness = 800 * kScale;
          params.dynamicsStiffness = 800 * kScale;
          MultiFingerGrasp grasp(b.model, b.mass, static_cast<int>(hand.size()), params);
          std::vector<hg::Vec3> tips(hand.size());
          const int ticks = static_cast<int>(0.5 / dt);
          double largest = 0;
          for (int i = 0; i < ticks; ++i) {
            const double t = i * dt;
            for (std::size_t j = 0; j < tips.size(); ++j)  // squeeze, shake sideways and lift
              tips[j] = hand[j] * half * (1 - 0.02 * std::sin(6 * t)) +
                        hg::Vec3(0.3 * half * std::sin(9 * t), 0, 0.1 * half * std::sin(4 * t));
            const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
            ASSERT_TRUE(o.body.position.allFinite());
            ASSERT_TRUE(o.body.rotation.allFinite());
            for (const FingerOutput& f : o.fingers) {
              ASSERT_TRUE(f.force.allFinite());
              ASSERT_TRUE(f.torsion.allFinite());
              largest = std::max(largest, f.force.norm());
            }
          }
          const double bound = 10 * (params.stiffness * 2 * half + b.mass.mass_kg * 9.81 * 5) + 1;
          EXPECT_LT(largest, bound);
          EXPECT_LT(grasp.output().body.position.norm(), 100.0);
        }
      }
    }
  }
}

TEST(MultiFingerGrasp, ConventionalStepIsAllocationFree) {
  const Block b = block(60, 60, 100, 1.0);
  MultiFingerParams params;
  params.method = Method::Conventional;
  params.contactDampingRatio = 0.5;
  MultiFingerGrasp grasp(b.model, b.mass, 3, params);
  const std::vector<hg::Vec3> tips{{0.0275, 0, 0}, {-0.0275, 0.01, 0}, {-0.0275, -0.01, 0}};
  for (int i = 0; i < 20; ++i) grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), 1e-3);
  const long before = hg::test::allocations();
  for (int i = 0; i < 500; ++i) grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), 1e-3);
  EXPECT_EQ(hg::test::allocations(), before);
  EXPECT_EQ(grasp.output().contacts, 3);
}

namespace {

// The five-finger layout that once ran away (finger forces ~2000 N): thumb and index on
// the −x and +x faces, a middle finger on +y and a ring finger on +z, none opposed on its
// axis. Units of the block's half size; the first `count` fingers are used.
const std::vector<hg::Vec3> kRunawayHand{
    {0.95, 0, 0}, {-0.95, 0.3, 0}, {-0.95, -0.3, 0}, {0, 0.95, 0.2}, {0.3, 0, 0.95}};

struct ShakeRun {
  double largestForce = 0;     // over all fingers and ticks [N]
  double largestPosition = 0;  // |body position| [m]
  bool finite = true;
};

// The hand shakes the 60 mm block 0.3 half · sin(9 t) along x, fingertips 1.5 mm inside.
// dtAt(i) gives tick i's dt (jitter); the run lasts `seconds`.
template <typename DtAt>
ShakeRun shakeLayout(Method method, int count, double seconds, DtAt dtAt, double stiffness = 800) {
  const Block b = block(60, 60, 60, 1.0);
  const double half = 0.03;
  MultiFingerParams params;
  params.method = method;
  params.stiffness = stiffness;
  params.dynamicsStiffness = stiffness;
  MultiFingerGrasp grasp(b.model, b.mass, count, params);
  std::vector<hg::Vec3> tips(count);
  ShakeRun r;
  double t = 0;
  for (int i = 0; t < seconds; ++i) {
    const double dt = dtAt(i);
    t += dt;
    for (int j = 0; j < count; ++j) tips[j] = kRunawayHand[j] * half + hg::Vec3(0.3 * half * std::sin(9 * t), 0, 0);
    const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
    if (!o.body.position.allFinite() || !o.body.rotation.allFinite()) r.finite = false;
    for (const FingerOutput& f : o.fingers) {
      if (!f.force.allFinite() || !f.torsion.allFinite()) r.finite = false;
      r.largestForce = std::max(r.largestForce, f.force.norm());
    }
    r.largestPosition = std::max(r.largestPosition, o.body.position.norm());
    if (!r.finite) break;
  }
  return r;
}

// A sane bound for that hand: each spring at most a few times k × (1.5 mm + the shake's
// amplitude of 9 mm), plus a few times the block's weight and shake inertia.
double runawayBound(double stiffness) {
  const double depth = 0.0015 + 0.3 * 0.03;
  return 5 * stiffness * depth + 5 * (1.0 * 9.81 + 1.0 * 0.3 * 0.03 * 81);
}

}  // namespace

TEST(MultiFingerGrasp, FiveFingerUnopposedLayoutDoesNotRunAway) {
  const ShakeRun r = shakeLayout(Method::Proposed, 5, 5.0, [](int) { return 1e-3; });
  std::printf("five-finger layout: largest force %.4g N, largest |position| %.4g m\n", r.largestForce,
              r.largestPosition);
  EXPECT_TRUE(r.finite);
  EXPECT_LT(r.largestForce, runawayBound(800));
  EXPECT_LT(r.largestPosition, 0.1);
}

// The same layout with 2–5 of its fingers, dt 1e-4..5e-3 and a jittery servo clock (dt
// ×0.3..×3 of 1 ms, now and then a 10 ms stall): never NaN, forces bounded.
TEST(MultiFingerGrasp, UnopposedLayoutStaysBoundedOverDtAndJitter) {
  for (int count = 2; count <= 5; ++count) {
    for (double dt : {1e-4, 3e-4, 1e-3, 2e-3, 5e-3}) {
      SCOPED_TRACE(testing::Message() << count << " fingers dt " << dt);
      const ShakeRun r = shakeLayout(Method::Proposed, count, dt < 5e-4 ? 1.5 : 4.0, [dt](int) { return dt; });
      EXPECT_TRUE(r.finite);
      EXPECT_LT(r.largestForce, runawayBound(800));
      EXPECT_LT(r.largestPosition, 0.1);
    }
    SCOPED_TRACE(testing::Message() << count << " fingers, jittery dt");
    std::mt19937 random(count);
    std::uniform_real_distribution<double> jitter(0.3, 3.0);
    const ShakeRun r = shakeLayout(Method::Proposed, count, 4.0, [&](int i) {
      return i % 397 == 0 ? 1e-2 : 1e-3 * jitter(random);
    });
    EXPECT_TRUE(r.finite);
    EXPECT_LT(r.largestForce, runawayBound(800));
    EXPECT_LT(r.largestPosition, 0.1);
  }
}

// Step 8's slip: a twist beyond what torsional friction holds turns the part the way the
// twist pushes it, spinning up as under kinetic friction at any dt; the fingers feel no
// more than their torsional limit, and the spring never asks for more torque than the twist (the slip once turned the shell away from the
// part: it spun both ways at hundreds of rad/s and asked ±3 N m of a 0.2 N m twist).
TEST(MultiFingerGrasp, SlipTurnsThePartWithTheTwistAndStaysBounded) {
  const Block b = block(60, 60, 100, 1.0);
  for (double dt : {1e-4, 1e-3, 5e-3}) {
    SCOPED_TRACE(testing::Message() << "dt " << dt);
    MultiFingerParams params;
    params.gravity = hg::Vec3(0, 0, -2.0);
    MultiFingerGrasp grasp(b.model, b.mass, 2, params);
    const std::vector<hg::Vec3> tips{{0.0275, 0, 0}, {-0.0275, 0, 0}};
    const double twist = 0.2;
    for (double t = 0; t < 1.0; t += dt) grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
    double turned = 0, fastest = 0;  // about +x, unwrapped
    for (double t = 0; t < 3.0; t += dt) {
      const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3(twist, 0, 0), dt);
      const double w = grasp.body().angularVelocity().x();
      turned += dt * w;
      fastest = std::max(fastest, std::abs(w));
      ASSERT_GT(w, -1e-6) << t;  // never turned back against the twist
      ASSERT_LT(o.resultantTorque.norm(), 1.1 * twist) << t;
      for (int j = 0; j < 2; ++j) {
        const FingerOutput& f = o.fingers[j];
        ASSERT_LE(f.torsion.norm(), params.torsionalFriction * std::max(0.0, f.force.dot(f.normal)) + 1e-9) << t;
        ASSERT_LT(f.force.norm(), 10.0) << t;
      }
    }
    // Kinetic torsional friction: the part spins up under the twist less what the fingers
    // hold, I ω̇ = τ − μ_t Σ F_n, whatever dt.
    double held = 0;
    for (int j = 0; j < 2; ++j) held += grasp.output().fingers[j].torsion.norm();
    const double spunUp = (twist - held) / b.mass.inertia_kgm2(0, 0) * 3.0;
    std::printf("dt %g: turned %.3g rad, fastest %.3g rad/s (expected %.3g)\n", dt, turned, fastest, spunUp);
    EXPECT_TRUE(grasp.output().slipping);
    EXPECT_NEAR(fastest, spunUp, 0.15 * spunUp);
  }
}

namespace {

// Four fingers on the ±x faces at staggered heights: their normal pushes span F_x, N_y and
// N_z, so a resultant along x (the shake) with no weight is feasible for eq 19 alone.
const std::vector<hg::Vec3> kStaggeredHand{
    {0.95, 0.5, 0.5}, {0.95, -0.5, -0.5}, {-0.95, 0.5, -0.5}, {-0.95, -0.5, 0.5}};

}  // namespace

// Issue 6 in 6 DOF: eq 19's shares never lower a finger's grasping force (each finger's
// normal force is its grasping spring's plus k_i ≥ 0), and the fingers give the part its
// resultant whenever the normals can (no friction, no weight: eq 19 alone answers).
TEST(MultiFingerGrasp, DistributionNeverLowersGraspingForceAndMatchesFeasibleResultant) {
  const Block b = block(60, 60, 60, 1.0);
  const double half = 0.03, dt = 1e-3;
  MultiFingerParams params;
  params.gravity = hg::Vec3::Zero();
  params.friction = 0;
  params.torsionalFriction = 0;
  MultiFingerGrasp grasp(b.model, b.mass, 4, params);
  std::vector<hg::Vec3> tips(4);
  double largestResultant = 0, largestShare = 0;
  for (int i = 0; i < 4000; ++i) {
    const double t = i * dt;
    for (int j = 0; j < 4; ++j) tips[j] = kStaggeredHand[j] * half + hg::Vec3(0.3 * half * std::sin(9 * t), 0, 0);
    const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
    ASSERT_EQ(o.contacts, 4) << t;
    for (int j = 0; j < 4; ++j) {
      const FingerOutput& f = o.fingers[j];
      const double springNormal = params.stiffness * (f.proxy - tips[j]).dot(f.normal);
      EXPECT_GE(f.share, 0) << t;
      EXPECT_GE(f.force.dot(f.normal), springNormal - 1e-9) << t;
      EXPECT_NEAR(f.force.dot(f.normal), springNormal + f.share, 1e-9) << t;
      largestShare = std::max(largestShare, f.share);
    }
    const double scale = o.resultantForce.norm() + o.resultantTorque.norm() / half;
    largestResultant = std::max(largestResultant, o.resultantForce.norm());
    EXPECT_LE(o.unmatchedForce.norm(), 0.02 * scale + 1e-6) << t;
    EXPECT_LE(o.unmatchedTorque.norm() / half, 0.02 * scale + 1e-6) << t;
  }
  EXPECT_GT(largestResultant, 1.0);  // the shake really needed a resultant
  EXPECT_GT(largestShare, 0.5);
}

namespace {

struct ExtremeCase {
  const char* name;
  double size_mm, kg, stiffness;
  std::vector<hg::Vec3> tips;  // in units of the half size
};

// Largest finger force over a 2 s shake (0.2 half · sin 9t along x, 2 % squeeze); false
// on a NaN anywhere.
template <typename DtAt>
bool shakeExtreme(const ExtremeCase& c, Method method, DtAt dtAt, double& largest) {
  const Block b = block(c.size_mm, c.size_mm, c.size_mm, c.kg);
  const double half = 0.5e-3 * c.size_mm;
  MultiFingerParams params;
  params.method = method;
  params.stiffness = c.stiffness;
  params.dynamicsStiffness = c.stiffness;
  MultiFingerGrasp grasp(b.model, b.mass, static_cast<int>(c.tips.size()), params);
  std::vector<hg::Vec3> tips(c.tips.size());
  largest = 0;
  double t = 0;
  for (int i = 0; t < 2.0; ++i) {
    const double dt = dtAt(i);
    t += dt;
    for (std::size_t j = 0; j < tips.size(); ++j)
      tips[j] = c.tips[j] * half * (1 - 0.02 * std::sin(6 * t)) + hg::Vec3(0.2 * half * std::sin(9 * t), 0, 0);
    const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
    if (!o.body.position.allFinite() || !o.body.rotation.allFinite() || !o.shell.position.allFinite()) return false;
    for (const FingerOutput& f : o.fingers) {
      if (!f.force.allFinite() || !f.torsion.allFinite()) return false;
      largest = std::max(largest, f.force.norm());
    }
  }
  return true;
}

// A physical bound: a few times each spring over the deepest a fingertip gets (its depth
// plus the squeeze and the shake) and the part's weight and shake inertia.
double physicalBound(const ExtremeCase& c) {
  const double half = 0.5e-3 * c.size_mm;
  double depth = 0;
  for (const hg::Vec3& p : c.tips) depth = std::max(depth, (1 - p.cwiseAbs().maxCoeff()) * half);
  depth += 0.02 * half + 0.2 * half;
  const double weightAndInertia = c.kg * (9.81 + 0.2 * half * 81);
  return 5 * (c.stiffness * depth + weightAndInertia) + 0.1;
}

}  // namespace

// Issue 6's extremes in 6 DOF, both methods: stiff springs (1e5 N/m), a 1 mm part, a
// 100 kg part, five fingers on one face, fingers on opposite edges; dt 1e-4..5e-3 and a
// jittery clock: no NaN, and forces within a few times springs × depth + weight.
TEST(MultiFingerGrasp, ExtremePartsAndSpringsStayWithinPhysicalBounds) {
  const std::vector<hg::Vec3> opposed{{0.95, 0, 0}, {-0.95, 0, 0}, {0, 0.95, 0}};
  const std::vector<ExtremeCase> cases{
      {"stiff springs", 60, 1.0, 1e5, opposed},
      {"tiny part", 1, 1e-5, 800, opposed},
      {"tiny part, stiff", 1, 1e-5, 1e5, opposed},
      {"heavy part", 200, 100.0, 800, opposed},
      {"heavy part, stiff", 200, 100.0, 1e5, opposed},
      {"five on one face", 60, 1.0, 800,
       {{0, 0, 0.95}, {0.5, 0, 0.95}, {-0.5, 0, 0.95}, {0, 0.5, 0.95}, {0, -0.5, 0.95}}},
      {"five on one face, stiff", 60, 1.0, 1e5,
       {{0, 0, 0.95}, {0.5, 0, 0.95}, {-0.5, 0, 0.95}, {0, 0.5, 0.95}, {0, -0.5, 0.95}}},
      {"opposite edges", 60, 1.0, 800, {{0.97, 0, 0.97}, {-0.97, 0, -0.97}}},
      {"opposite edges, stiff", 60, 1.0, 1e5, {{0.97, 0, 0.97}, {-0.97, 0, -0.97}}},
  };
  for (const ExtremeCase& c : cases) {
    for (Method method : {Method::Conventional, Method::Proposed}) {
      const char* name = method == Method::Conventional ? "conventional" : "proposed";
      for (double dt : {1e-4, 1e-3, 5e-3}) {
        SCOPED_TRACE(testing::Message() << c.name << ", " << name << ", dt " << dt);
        double largest = 0;
        EXPECT_TRUE(shakeExtreme(c, method, [dt](int) { return dt; }, largest));
        EXPECT_LT(largest, physicalBound(c));
      }
      SCOPED_TRACE(testing::Message() << c.name << ", " << name << ", jittery dt");
      std::mt19937 random(7);
      std::uniform_real_distribution<double> jitter(0.3, 3.0);
      double largest = 0;
      EXPECT_TRUE(shakeExtreme(c, method, [&](int i) { return i % 211 == 0 ? 1e-2 : 1e-3 * jitter(random); }, largest));
      EXPECT_LT(largest, physicalBound(c));
    }
  }
}

// A device that sends NaN for one tick (or a zero or NaN dt, or a NaN load): the grasp
// keeps its whole state, and the next finite sample gives exactly what it would have
// given had the bad tick never come.
TEST(MultiFingerGrasp, NonFiniteTickLeavesTheStateAndTheNextSampleContinues) {
  const Block b = block(60, 60, 100, 1.0);
  for (Method method : {Method::Conventional, Method::Proposed}) {
    SCOPED_TRACE(method == Method::Conventional ? "conventional" : "proposed");
    MultiFingerParams params;
    params.method = method;
    params.contactDampingRatio = 0.3;  // the conventional dampers use the last fingertips
    params.gravity = hg::Vec3(0, 0, -2.0);
    MultiFingerGrasp grasp(b.model, b.mass, 3, params), twin(b.model, b.mass, 3, params);
    std::vector<hg::Vec3> tips(3);
    auto hand = [&](double t) {
      const hg::Vec3 wrist(0.01 * std::sin(7 * t), 0.005 * std::sin(5 * t), 0);
      tips = {hg::Vec3(0.0275, 0, 0) + wrist, hg::Vec3(-0.0275, 0.01, 0) + wrist, hg::Vec3(-0.0275, -0.01, 0) + wrist};
    };
    const double dt = 1e-3;
    int tick = 0;
    for (; tick < 700; ++tick) {
      hand(tick * dt);
      grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
      twin.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
    }
    const MultiFingerOutput before = grasp.output();
    const hg::Vec3 v = grasp.body().velocity(), w = grasp.body().angularVelocity();
    ASSERT_EQ(before.contacts, 3);
    hand(tick * dt);
    std::vector<hg::Vec3> bad = tips;
    bad[1].y() = NAN;
    grasp.step(bad, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
    grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), 0.0);
    grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), NAN);
    grasp.step(tips, hg::Vec3(NAN, 0, 0), hg::Vec3::Zero(), dt);
    grasp.step(tips, hg::Vec3::Zero(), hg::Vec3(0, INFINITY, 0), dt);
    const MultiFingerOutput& after = grasp.output();
    EXPECT_EQ(after.body.position, before.body.position);
    EXPECT_EQ(after.body.rotation, before.body.rotation);
    EXPECT_EQ(after.shell.position, before.shell.position);
    EXPECT_EQ(grasp.body().velocity(), v);
    EXPECT_EQ(grasp.body().angularVelocity(), w);
    for (int j = 0; j < 3; ++j) EXPECT_EQ(after.fingers[j].force, before.fingers[j].force) << j;
    for (int k = 0; k < 300; ++k, ++tick) {
      hand(tick * dt);
      const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
      const MultiFingerOutput& r = twin.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
      for (int j = 0; j < 3; ++j) EXPECT_EQ(o.fingers[j].force, r.fingers[j].force) << k << " " << j;
      EXPECT_EQ(o.body.position, r.body.position) << k;
    }
  }
}

// Eq 19 with two fingers a little out of line (0.5–5 mm across a 55 mm grip): a torque
// across their line would need opposed pushes of N / offset. No finger is given more than
// the whole resultant, |F| + |N| / L, and the force along the grasp (the shake) is still
// given: clipping each share to the cap once lost all of it (7.8 of 7.9 N).
TEST(MultiFingerGrasp, NearlyCollinearFingersKeepTheForceWithinTheCap) {
  const Block b = block(60, 60, 100, 1.0);
  for (double offset : {0.5e-3, 2e-3, 5e-3}) {
    SCOPED_TRACE(testing::Message() << "offset " << offset);
    MultiFingerParams params;
    params.gravity = hg::Vec3(0, 0, -2.0);
    MultiFingerGrasp grasp(b.model, b.mass, 2, params);
    const double dt = 1e-3;
    double largestResultant = 0, largestUnmatched = 0;
    long allocations = 0;
    std::vector<hg::Vec3> tips(2);
    for (int i = 0; i < 6000; ++i) {
      const double w = 0.03 * std::sin(9 * i * dt);
      tips[0] = hg::Vec3(w + 0.0275, 0, 0.01 + offset);
      tips[1] = hg::Vec3(w - 0.0275, 0, 0.01);
      const long before = hg::test::allocations();
      const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
      allocations += hg::test::allocations() - before;
      ASSERT_EQ(o.contacts, 2);
      const hg::Vec3 centre = o.shell.pointToAbsolute(b.mass.centre_m);
      const double L = std::sqrt(0.5 * ((o.fingers[0].proxy - centre).squaredNorm() +
                                        (o.fingers[1].proxy - centre).squaredNorm()));
      const double cap = o.resultantForce.norm() + o.resultantTorque.norm() / L;
      for (int j = 0; j < 2; ++j) EXPECT_LE(o.fingers[j].share, cap * (1 + 1e-9)) << i;
      largestResultant = std::max(largestResultant, std::abs(o.resultantForce.x()));
      largestUnmatched = std::max(largestUnmatched, std::abs(o.unmatchedForce.x()));
    }
    EXPECT_GT(largestResultant, 3.0);
    EXPECT_LT(largestUnmatched, 0.15 * largestResultant);
    EXPECT_EQ(allocations, 0);  // the second solve too
  }
}

// Random layouts of 2–5 fingers on the block's faces, shaken along a random direction:
// never NaN, forces within the sane bound. (Before the slip fix most such layouts ran
// away: 183 of 300 in a longer run of this kind.)
TEST(MultiFingerGrasp, RandomLayoutsStayBounded) {
  const Block b = block(60, 60, 60, 1.0);
  std::mt19937 random(42);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 80; ++trial) {
    const int count = 2 + trial % 4;
    const double dt = std::array<double, 3>{1e-4, 1e-3, 3e-3}[trial % 3];
    std::vector<hg::Vec3> hand(count);
    for (hg::Vec3& h : hand) {  // on a random face, 1.5 mm deep
      h = 0.9 * hg::Vec3(u(random), u(random), u(random));
      h[random() % 3] = u(random) > 0 ? 0.95 : -0.95;
    }
    const hg::Vec3 direction = hg::Vec3(u(random), u(random), u(random)).normalized();
    SCOPED_TRACE(testing::Message() << "trial " << trial << ", " << count << " fingers, dt " << dt);
    MultiFingerGrasp grasp(b.model, b.mass, count, MultiFingerParams{});
    std::vector<hg::Vec3> tips(count);
    double largest = 0;
    for (double t = 0; t < 2.0; t += dt) {
      for (int j = 0; j < count; ++j) tips[j] = 0.03 * hand[j] + 0.009 * std::sin(9 * t) * direction;
      const MultiFingerOutput& o = grasp.step(tips, hg::Vec3::Zero(), hg::Vec3::Zero(), dt);
      ASSERT_TRUE(o.body.position.allFinite());
      for (const FingerOutput& f : o.fingers) {
        ASSERT_TRUE(f.force.allFinite());
        largest = std::max(largest, f.force.norm());
      }
    }
    EXPECT_LT(largest, runawayBound(800));
  }
}
