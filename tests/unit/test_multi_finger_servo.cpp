// The resultant-force method over a scene and on the servo thread: three to five
// fingertips of a scripted hand pinch a cylinder resting in a scene with a far box, lift it
// (only once friction can carry its weight), carry it and put it down, where it stays; the
// far box is never queried and never moves; no allocation per tick; the loop refuses a
// device with too few fingertips.
#include <gtest/gtest.h>

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <gp_Ax2.hxx>

#include <chrono>
#include <cstdio>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/grasp/multi_finger/multi_finger_scene.hpp"
#include "hapticgrasp/servo/grasp_engine.hpp"
#include "hapticgrasp/servo/scripted_hand_device.hpp"
#include "hapticgrasp/servo/pose_tracker.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"

namespace hg {
namespace {

using grasp::GraspState;
using grasp::multi_finger::MultiFingerScene;

constexpr double kRadius = 0.03;     // the cylinder: 60 mm across, 100 mm high, axis z
constexpr double kMass = 0.2;        // kg
constexpr double kDepth = 0.003;     // how far each closed fingertip sits inside
constexpr double kLift = 0.05, kCarry = 0.03;  // the hand lifts 50 mm and carries 30 mm along x
const Vec3 kFarBox(0.5, 0, 0);

grasp::ScenePtr scene() {
  const gp_Ax2 axis(gp_Pnt(0, 0, -50), gp_Dir(0, 0, 1));
  auto cylinder = geometry::PartModel::fromShape(BRepPrimAPI_MakeCylinder(axis, 1000 * kRadius, 100).Shape(),
                                                 geometry::LengthUnit::Millimetre, "cylinder");
  auto box = geometry::PartModel::fromShape(BRepPrimAPI_MakeBox(gp_Pnt(-20, -20, -20), 40, 40, 40).Shape(),
                                            geometry::LengthUnit::Millimetre, "box");
  grasp::PartPose far;
  far.position = kFarBox;
  return std::make_shared<const grasp::Scene>(std::vector<grasp::ScenePart>{
      grasp::makeScenePart(cylinder, geometry::MassSpec::mass(kMass), {}, geometry::Backend::Exact),
      grasp::makeScenePart(box, geometry::MassSpec::mass(1.0), far, geometry::Backend::Exact)});
}

// `n` fingertips evenly round the cylinder's axis at mid-height, `radius` from it.
grasp::HandKey ring(double t, int n, double radius, const Vec3& shift) {
  grasp::HandKey key;
  key.t = t;
  key.shift = shift;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * k / n + 0.3;
    key.fingertip(k) = Vec3(radius * std::cos(a), radius * std::sin(a), 0);
  }
  return key;
}

// Open, close round the cylinder, lift and carry, hold, open: 2.2 s.
grasp::HandScript pinchLiftCarry(int n) {
  const double open = kRadius + 0.01, closed = kRadius - kDepth;
  const Vec3 up(kCarry, 0, kLift);
  return grasp::HandScript({ring(0.0, n, open, Vec3::Zero()), ring(0.3, n, closed, Vec3::Zero()),
                            ring(0.5, n, closed, Vec3::Zero()), ring(1.2, n, closed, up), ring(1.6, n, closed, up),
                            ring(1.8, n, open, up), ring(2.2, n, open, up)});
}

std::vector<Vec3> tipsAt(const grasp::HandSample& hand, int n) {
  std::vector<Vec3> tips;
  for (int k = 0; k < n; ++k) tips.push_back(hand.fingertip(k));
  return tips;
}

class MultiFingerSceneTest : public ::testing::TestWithParam<int> {};

TEST_P(MultiFingerSceneTest, PinchLiftCarryPutDown) {
  const int n = GetParam();
  const auto parts = scene();
  MultiFingerScene method(parts, n);
  const grasp::HandScript script = pinchLiftCarry(n);
  const double dt = 1e-3;
  std::uint32_t seen = 0;
  double maxForce = 0, liftTime = -1, releaseTime = -1;
  int maxQueried = 0;
  grasp::PartPose atRelease;
  for (double t = 0; t < 2.2; t += dt) {
    const auto tips = tipsAt(script.at(t), n);
    const auto& o = method.step(tips, dt);
    ASSERT_TRUE(o.validSample);
    seen |= o.events;
    maxQueried = std::max(maxQueried, o.queried);
    for (int k = 0; k < n; ++k) {
      ASSERT_TRUE(o.force[k].allFinite());
      maxForce = std::max(maxForce, o.force[k].norm());
    }
    if ((o.events & grasp::kLift) && liftTime < 0) liftTime = t;
    if ((o.events & grasp::kRelease) && releaseTime < 0) {
      releaseTime = t;
      atRelease = o.poses[0];
    }
    // The far box is never queried and never moves.
    EXPECT_EQ(o.poses[1].position, kFarBox);
    if (t > 1.4 && t < 1.6) {
      EXPECT_EQ(o.state, GraspState::Manipulate) << "t=" << t;
    }
  }
  std::printf("%d fingers: lift at %.3f s, put down at %.3f s at (%.2f, %.2f, %.2f) mm, max fingertip force %.2f N\n",
              n, liftTime, releaseTime, 1e3 * atRelease.position.x(), 1e3 * atRelease.position.y(),
              1e3 * atRelease.position.z(), maxForce);
  EXPECT_EQ(maxQueried, 1);
  EXPECT_TRUE(seen & grasp::kIndexContact);
  EXPECT_TRUE(seen & grasp::kGrasp);
  EXPECT_TRUE(seen & grasp::kRelease);
  // Lifted only once the fingers were in far enough for friction to carry the weight.
  EXPECT_GT(liftTime, 0.1);
  EXPECT_LT(liftTime, 0.5);
  ASSERT_GT(releaseTime, 1.6);
  // Carried with the hand: up and along by the script's amounts, less the sag of the
  // dynamics spring (m g / k_d = 2.5 mm) and a little lag.
  EXPECT_NEAR(atRelease.position.x(), kCarry, 0.004);
  EXPECT_NEAR(atRelease.position.z(), kLift, 0.006);
  // Put down: it rests where the fingers left it.
  EXPECT_EQ(method.state(), GraspState::Free);
  EXPECT_EQ(method.poses()[0].position, atRelease.position);
  // Bounded: no finger ever feels more than its spring at twice the closing depth plus the weight.
  EXPECT_LT(maxForce, 800 * 2 * kDepth + kMass * 9.81);
}

INSTANTIATE_TEST_SUITE_P(Fingers, MultiFingerSceneTest, ::testing::Values(3, 4, 5));

// A scene of 1,000 cylinders 0.2 m apart: the hand pinches, lifts and carries number 537
// as it would the only part; only the parts near a fingertip cost anything, and the rest
// never move.
TEST(MultiFingerScene, OnePartOfAThousandIsCarriedAsIfAlone) {
  const grasp::ScenePart one = scene()->part(0);
  std::vector<grasp::ScenePart> parts;
  for (int i = 0; i < 1000; ++i) {
    grasp::ScenePart p = one;
    p.initialPose.position = Vec3(0.2 * (i % 40), 0.2 * (i / 40), 0);
    parts.push_back(p);
  }
  const int target = 537;
  const Vec3 at = parts[target].initialPose.position;
  MultiFingerScene method(std::make_shared<const grasp::Scene>(std::move(parts)), 3);
  const grasp::HandScript script = pinchLiftCarry(3);
  std::uint32_t seen = 0;
  int maxQueried = 0;
  for (double t = 0; t < 2.2; t += 1e-3) {
    auto tips = tipsAt(script.at(t), 3);
    for (Vec3& x : tips) x += at;
    const auto& o = method.step(tips, 1e-3);
    seen |= o.events;
    maxQueried = std::max(maxQueried, o.queried);
    EXPECT_EQ(o.unbound, 0);
    if (t > 1.4 && t < 1.6) {
      ASSERT_EQ(o.state, GraspState::Manipulate) << t;
      ASSERT_EQ(o.graspedPart, target);
      ASSERT_EQ(method.carriedParts().size(), 1u);
      EXPECT_EQ(method.carriedParts()[0], target);
    }
  }
  EXPECT_TRUE(seen & grasp::kLift);
  EXPECT_TRUE(seen & grasp::kRelease);
  EXPECT_EQ(maxQueried, 1);
  EXPECT_NEAR(method.poses()[target].position.x() - at.x(), kCarry, 0.004);
  EXPECT_NEAR(method.poses()[target].position.z() - at.z(), kLift, 0.006);
  for (int i = 0; i < 1000; ++i) {
    if (i != target) {
      ASSERT_EQ(method.poses()[static_cast<std::size_t>(i)].position.z(), 0) << i;
    }
  }
}

// More parts round one fingertip than the pool holds: the nearest kPool are stepped and
// the rest counted, never silently dropped.
TEST(MultiFingerScene, SaysWhenMorePartsAreNearThanItsPoolHolds) {
  const grasp::ScenePart one = scene()->part(0);
  std::vector<grasp::ScenePart> parts(MultiFingerScene::kPool + 4, one);
  MultiFingerScene method(std::make_shared<const grasp::Scene>(std::move(parts)), 1);
  const std::vector<Vec3> tip{Vec3(kRadius - 0.001, 0, 0)};
  const auto& o = method.step(tip, 1e-3);
  EXPECT_EQ(o.unbound, 4);
  EXPECT_EQ(o.queried, MultiFingerScene::kPool);
  EXPECT_GE(o.part[0], 0);
}

TEST(MultiFingerScene, TooWeakAPinchDoesNotLift) {
  // Two fingers just touching (0.2 mm in: 0.16 N each, μ·squeeze 0.32 N < 1.96 N): GRASP, never carried.
  MultiFingerScene method(scene(), 2);
  const std::vector<Vec3> tips{{kRadius - 0.0002, 0, 0}, {-(kRadius - 0.0002), 0, 0}};
  std::uint32_t seen = 0;
  for (int i = 0; i < 500; ++i) seen |= method.step(tips, 1e-3).events;
  EXPECT_EQ(method.state(), GraspState::Grasp);
  EXPECT_FALSE(seen & grasp::kLift);
  EXPECT_EQ(method.poses()[0].position, Vec3::Zero());
}

TEST(MultiFingerScene, PressingFromAboveNeverLifts) {
  // Two fingers pressing hard on the top face squeeze nothing: the part stays on its support.
  MultiFingerScene method(scene(), 2);
  const std::vector<Vec3> tips{{0.01, 0, 0.045}, {-0.01, 0, 0.045}};
  for (int i = 0; i < 500; ++i) method.step(tips, 1e-3);
  EXPECT_FALSE(method.carried(0));
  EXPECT_EQ(method.poses()[0].position, Vec3::Zero());
  EXPECT_GT(method.step(tips, 1e-3).force[0].z(), 3.0);  // 5 mm in: 4 N up on the finger
}

TEST(MultiFingerScene, NonFiniteInputChangesNothingAndStepIsAllocationFree) {
  MultiFingerScene method(scene(), 3);
  const grasp::HandScript script = pinchLiftCarry(3);
  double t = 0;
  for (; t < 0.8; t += 1e-3) method.step(tipsAt(script.at(t), 3), 1e-3);
  ASSERT_EQ(method.state(), GraspState::Manipulate);
  const grasp::PartPose before = method.poses()[0];
  std::vector<Vec3> bad = tipsAt(script.at(t), 3);
  bad[2].y() = NAN;
  const auto& o = method.step(bad, 1e-3);
  EXPECT_FALSE(o.validSample);
  EXPECT_EQ(o.force[0], Vec3::Zero());
  EXPECT_EQ(method.poses()[0].position, before.position);
  EXPECT_FALSE(method.step(tipsAt(script.at(t), 3), NAN).validSample);
  EXPECT_FALSE(method.step(tipsAt(script.at(t), 2), 1e-3).validSample);  // wrong finger count

  std::vector<std::vector<Vec3>> tips;
  for (double s = t; s < 2.2; s += 1e-3) tips.push_back(tipsAt(script.at(s), 3));
  const long allocations = test::allocations();
  for (const auto& p : tips) method.step(p, 1e-3);
  EXPECT_EQ(test::allocations(), allocations);
  EXPECT_EQ(method.state(), GraspState::Free);
}

TEST(MultiFingerScene, ResetPutsEveryPartBack) {
  MultiFingerScene method(scene(), 3);
  const grasp::HandScript script = pinchLiftCarry(3);
  for (double t = 0; t < 1.0; t += 1e-3) method.step(tipsAt(script.at(t), 3), 1e-3);
  ASSERT_GT(method.poses()[0].position.z(), 0.01);
  method.reset();
  EXPECT_EQ(method.poses()[0].position, Vec3::Zero());
  EXPECT_EQ(method.state(), GraspState::Free);
  EXPECT_THROW(MultiFingerScene(scene(), 6), std::invalid_argument);
  EXPECT_THROW(MultiFingerScene(nullptr, 3), std::invalid_argument);
}

// On the real servo thread at 1 kHz with a scripted three-fingered hand.
TEST(MultiFingerServo, ThreeFingeredHandCarriesThePartOnTheServoThread) {
  device::DeviceSpec spec = servo::ScriptedHandDevice::defaultSpec();
  spec.fingertips = 3;
  auto device = std::make_shared<servo::ScriptedHandDevice>(pinchLiftCarry(3), spec);
  servo::ServoConfig config;
  config.rate_hz = 1000;
  config.realtime = false;
  config.allocationCounter = &hg::servo::threadAllocations;
  servo::ServoLoop loop(device, std::make_unique<servo::MultiFingerEngine>(scene(), 3), config);
  servo::SnapshotReader reader;
  std::uint32_t seen = 0;
  servo::ServoSnapshot s;
  bool manipulated = false;
  loop.start();
  while (device->scriptTime() < 2.15) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (loop.read(s)) {
      seen |= reader.eventsSinceLastRead(s);
      manipulated |= s.state == GraspState::Manipulate;
    }
  }
  loop.stop();
  ASSERT_TRUE(loop.read(s));
  seen |= reader.eventsSinceLastRead(s);
  EXPECT_STREQ(s.method, "multi-finger");
  EXPECT_EQ(s.fingertips, 3);
  EXPECT_TRUE(manipulated);
  EXPECT_TRUE(seen & grasp::kLift);
  EXPECT_TRUE(seen & grasp::kRelease);
  EXPECT_EQ(s.state, GraspState::Free);
  servo::PoseTracker tracker({scene()->part(0).initialPose, scene()->part(1).initialPose});
  EXPECT_TRUE(tracker.update(s));  // the put-down is in the snapshot's log
  EXPECT_EQ(s.movingCount, 0);
  EXPECT_NEAR(tracker.pose(0).position.x(), kCarry, 0.006);
  EXPECT_NEAR(tracker.pose(0).position.z(), kLift, 0.008);
  EXPECT_EQ(tracker.pose(1).position, kFarBox);
  EXPECT_EQ(s.allocations, 0);
  EXPECT_EQ(s.watchdog.trips, 0u);
}

TEST(MultiFingerServo, RefusesADeviceWithTooFewFingertips) {
  auto device = std::make_shared<servo::ScriptedHandDevice>(pinchLiftCarry(2));  // two fingertips
  try {
    servo::ServoLoop loop(device, std::make_unique<servo::MultiFingerEngine>(scene(), 3));
    FAIL() << "a two-fingertip device was accepted for three fingers";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("needs 3 fingertips"), std::string::npos) << e.what();
  }
}

TEST(MultiFingerServo, NaNInAThirdFingertipTripsTheWatchdog) {
  grasp::HandSample hand;
  EXPECT_TRUE(hand.finite());
  hand.fingertip(4).z() = NAN;
  EXPECT_FALSE(hand.finite());
}

}  // namespace
}  // namespace hg
