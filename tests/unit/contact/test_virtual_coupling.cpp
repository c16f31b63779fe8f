// The virtual coupling with a scripted hand at 2 kHz: a peg enters a hole 0.1 mm wider
// than itself; a peg striking a 0.5 mm plate at 1 m/s never passes it; a block slides
// along a face with Coulomb's friction; a block pushed into a corner rests there; a block
// wedged between two parts and worked about gains the hand no energy. Penetration in
// contact stays within 0.05 mm, and a tick allocates nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "alloc_counter.hpp"
#include "contact/contact_fixtures.hpp"
#include "hapticgrasp/contact/virtual_coupling.hpp"

namespace hg::contact {
namespace {

constexpr double kRate_hz = 2000;
constexpr double kDt = 1 / kRate_hz;
constexpr double kSteadyPenetration_m = 5e-5;  // the target

struct Drive {
  double maxPenetration_m = 0;
  double minEnergy_J = 0;  // the hand's net work on the coupling, lowest over the run
  long allocations = 0;    // after the first tenth of the ticks
  grasp::PartPose last;
  CouplingOutput out;
};

// Steps the coupling for `seconds` with the hand at hand(t); `each` sees every tick.
// Tracks the work the hand does on the coupling (force and moment, both ports): a passive
// coupling never returns more than it was given.
Drive drive(VirtualCoupling& coupling, const ContactScene& scene, double seconds,
            const std::function<grasp::PartPose(double)>& hand,
            const std::function<void(double, const CouplingOutput&)>& each = {}) {
  Drive run;
  const int ticks = static_cast<int>(std::lround(seconds * kRate_hz));
  coupling.reset(hand(0));
  grasp::PartPose previous = hand(0);
  const Vec3 c = coupling.query().held().centre();
  double work = 0;
  long before = 0;
  for (int k = 1; k <= ticks; ++k) {
    if (k == ticks / 10) before = test::allocations();
    const grasp::PartPose h = hand(k * kDt);
    const CouplingOutput& out = coupling.step(h, kDt, scene, -1);
    // The operator pushes with -force: work += -F . dx - tau . dtheta.
    const Vec3 dx = h.pointToAbsolute(c) - previous.pointToAbsolute(c);
    const Eigen::AngleAxisd turn(h.rotation * previous.rotation.transpose());
    work += -out.force_N.dot(dx) - out.torque_Nm.dot(turn.angle() * turn.axis());
    previous = h;
    const Vec3 stretch = out.pose.pointToAbsolute(c) - h.pointToAbsolute(c);
    const Eigen::AngleAxisd twist(out.pose.rotation * h.rotation.transpose());
    const CouplingParameters& p = coupling.parameters();
    const double stored = 0.5 * p.stiffness.translational_N_m * stretch.squaredNorm() +
                          0.5 * p.stiffness.rotational_Nm_rad * twist.angle() * twist.angle();
    run.minEnergy_J = std::min(run.minEnergy_J, work - stored);
    run.maxPenetration_m = std::max(run.maxPenetration_m, out.penetration_m);
    if (each) each(k * kDt, out);
  }
  run.allocations = test::allocations() - before;
  run.last = coupling.output().pose;
  run.out = coupling.output();
  return run;
}

TEST(VirtualCoupling, APegEntersAHoleWithATenthOfAMillimetreClearance) {
  const ContactScene scene = test::sceneOf({test::holeBlockModel(0.1)});
  VirtualCoupling coupling(test::pegModel());
  // 0.3 mm off the axis (onto the chamfer) and tilted 0.1 deg, down at 20 mm/s from 3 mm
  // above to 15 mm deep, then held.
  const auto hand = [](double t) {
    return test::poseAt(Vec3(3e-4, 0, std::max(3e-3 - 0.02 * t, -15e-3)), 0.1 * std::numbers::pi / 180);
  };
  const Drive run = drive(coupling, scene, 1.1, hand);
  EXPECT_LT(run.last.position.z(), -14.5e-3);                                    // inserted
  EXPECT_LT(std::hypot(run.last.position.x(), run.last.position.y()), 0.06e-3);  // within the clearance
  EXPECT_LE(run.maxPenetration_m, kSteadyPenetration_m);
  EXPECT_EQ(run.allocations, 0);
  EXPECT_LT(run.out.force_N.x(), 0.0);  // the hand, 0.3 mm off the axis, is pushed back towards it
}

TEST(VirtualCoupling, APegStrikingAHalfMillimetrePlateAtOneMetreASecondDoesNotPassIt) {
  const ContactScene scene = test::sceneOf({test::plateModel(0.5)});
  for (const double tilt : {0.0, 0.7}) {  // flat face first, and rim first
    VirtualCoupling coupling(test::pegModel());
    const auto hand = [tilt](double t) { return test::poseAt(Vec3(0, 0, 10e-3 - 1.0 * t), tilt); };
    double lowest = 1;
    const Drive run = drive(coupling, scene, 0.04, hand, [&](double, const CouplingOutput& out) {
      // The peg's lowest point: its bottom rim, turned.
      const double r = test::kPegDiameter_mm / 2 * 1e-3;
      lowest = std::min(lowest, out.pose.position.z() - r * std::sin(tilt));
    });
    EXPECT_GT(lowest, -kSteadyPenetration_m) << "tilt " << tilt;  // never through, nor into it
    EXPECT_GT(run.last.position.z(), -1e-9) << "tilt " << tilt;   // resting on the plate's top face
    EXPECT_LE(run.maxPenetration_m, kSteadyPenetration_m);
    EXPECT_EQ(run.allocations, 0);
  }
}

TEST(VirtualCoupling, ABlockSlidesAlongAFaceWithCoulombsFriction) {
  const ContactScene scene = test::sceneOf({test::boxModel(-100, -50, -20, 200, 100, 20)});
  VirtualCoupling coupling(test::boxModel(-10, -10, 0, 20, 20, 10, 400));
  // Down from 1 mm above to 1 mm into the floor (2 N), then along x at 50 mm/s.
  const auto hand = [](double t) {
    return test::poseAt(Vec3(0.05 * std::max(t - 0.1, 0.0), 0, 1e-3 - 2e-3 * std::min(t / 0.1, 1.0)));
  };
  double ratio = 0;
  const Drive run = drive(coupling, scene, 0.5, hand, [&](double t, const CouplingOutput& out) {
    if (t > 0.3) ratio = -out.force_N.x() / out.force_N.z();
  });
  EXPECT_GT(run.last.position.x(), 15e-3);  // it went along
  EXPECT_NEAR(run.last.position.z(), 0, kSteadyPenetration_m);
  EXPECT_NEAR(ratio, 0.3, 0.03);  // the hand feels mu N against the motion
  EXPECT_LE(run.maxPenetration_m, kSteadyPenetration_m);
  EXPECT_EQ(run.allocations, 0);
}

TEST(VirtualCoupling, ABlockPushedIntoACornerRestsThere) {
  const ContactScene scene =
      test::sceneOf({test::boxModel(-100, -50, -20, 200, 100, 20), test::boxModel(0, -50, 0, 20, 100, 50)});
  VirtualCoupling coupling(test::boxModel(-20, -10, 0, 20, 20, 10, 400));
  // From 2 mm off both, into both by 0.5 mm, and held.
  const auto hand = [](double t) {
    const double s = std::min(t / 0.2, 1.0);
    return test::poseAt(Vec3(-2e-3 + s * 2.5e-3, 0, 2e-3 - s * 2.5e-3));
  };
  Vec3 halfway = Vec3::Zero();
  const Drive run = drive(coupling, scene, 1.0, hand, [&](double t, const CouplingOutput& out) {
    if (std::abs(t - 0.5) < kDt / 2) halfway = out.pose.position;
  });
  EXPECT_NEAR(run.last.position.x(), 0, kSteadyPenetration_m);
  EXPECT_NEAR(run.last.position.z(), 0, kSteadyPenetration_m);
  EXPECT_LT((run.last.position - halfway).norm(), 1e-6);  // at rest
  EXPECT_NEAR(run.out.force_N.x(), -1.0, 0.05);           // k 0.5 mm out of the wall
  EXPECT_NEAR(run.out.force_N.z(), 1.0, 0.05);            // and out of the floor
  EXPECT_LE(run.maxPenetration_m, kSteadyPenetration_m);
}

TEST(VirtualCoupling, ABlockWedgedBetweenTwoPartsGivesTheHandNoEnergy) {
  // A slot 20.02 mm wide between two blocks, on a floor; a 20 mm block pushed into it,
  // shaken sideways and twisted (it wedges across the slot), then pulled out.
  const ContactScene scene =
      test::sceneOf({test::boxModel(-100, -50, -30, 200, 100, 10), test::boxModel(-40, -50, -20, 29.99, 100, 20),
                     test::boxModel(10.01, -50, -20, 29.99, 100, 20)});
  CouplingParameters parameters;
  parameters.passivityController = false;  // the coupling itself must be passive
  VirtualCoupling coupling(test::boxModel(-10, -10, 0, 20, 20, 10, 400), parameters);
  const auto hand = [](double t) {
    const double depth = t < 1.5 ? std::min(t / 0.5, 1.0) * 21e-3 : std::max(21e-3 - (t - 1.5) * 0.05, -5e-3);
    const double shake = t > 0.5 && t < 1.5 ? 1e-3 * std::sin(2 * std::numbers::pi * 5 * t) : 0;
    const double twist = t > 0.5 && t < 1.5 ? 0.05 * std::sin(2 * std::numbers::pi * 3 * t) : 0;
    return test::poseAt(Vec3(shake, 0, 5e-3 - depth), twist, Vec3::UnitY());
  };
  const Drive run = drive(coupling, scene, 2.2, hand);
  EXPECT_GT(run.minEnergy_J, -1e-4);  // J: within rounding of the passivity limit
  EXPECT_LE(run.maxPenetration_m, kSteadyPenetration_m);
  EXPECT_GT(run.last.position.z(), 0);  // pulled back out
  EXPECT_EQ(run.allocations, 0);
}

}  // namespace
}  // namespace hg::contact
