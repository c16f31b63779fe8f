// The simulated arm driven by a live target (the workbench's "Simulated arm (mouse +
// keyboard)" device): placed where asked, pulled to the target, silent when not fed, and
// read()/write() allocate nothing (they run on the servo thread).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "alloc_counter.hpp"
#include "arm_input_device.hpp"
#include "hapticgrasp/sanitized.hpp"

using namespace hg;
using namespace std::chrono_literals;

namespace {

const Vec3 kRest(0.4, 0.1, 0.3);  // where the arm's resting grip centre is put (m)

device::HandTarget shifted(const device::ArmPose& p, const Vec3& d) { return {p.index + d, p.thumb + d, p.wrist + d}; }

// Reads and writes (zero force) every ~1 ms for `seconds`, feeding `target` every 10 ms.
device::DeviceSample drive(freecad::ArmInputDevice& arm, const device::HandTarget& target, double seconds) {
  device::DeviceSample sample;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (int i = 0; std::chrono::steady_clock::now() < end; ++i) {
    if (i % 10 == 0) arm.setTarget(target);
    arm.read(sample);
    arm.write(device::DeviceCommand{});
    std::this_thread::sleep_for(1ms);
  }
  return sample;
}

}  // namespace

TEST(ArmInputDevice, RestsWhereItWasPlacedWithItsGripAxisWhereAsked) {
  const freecad::ArmInputDevice own(kRest);
  const Vec3 u0 = own.gripAxis();
  EXPECT_NEAR(u0.norm(), 1.0, 1e-12);
  EXPECT_EQ(u0.z(), 0.0);
  std::printf("the arm's own grip axis (%.3f, %.3f, %.3f)\n", u0.x(), u0.y(), u0.z());
  freecad::ArmInputDevice arm(kRest, Vec3(0, 1, 0));
  const device::ArmPose& rest = arm.restPose();
  EXPECT_LT((0.5 * (rest.index + rest.thumb) - kRest).norm(), 1e-9);
  const Vec3 u = arm.gripAxis();
  EXPECT_NEAR(u.norm(), 1.0, 1e-12);
  EXPECT_LT((u - Vec3(0, 1, 0)).norm(), 1e-9);
  EXPECT_NEAR((arm.restWristOffset()).norm(), own.restWristOffset().norm(), 1e-9);
  EXPECT_TRUE(arm.spec().workspace.contains(kRest));
  const double open = (rest.index - rest.thumb).norm();
  std::printf("arm at rest: grip axis (%.3f, %.3f, %.3f), fingertips %.1f mm apart, wrist offset (%.1f, %.1f, %.1f) mm\n",
              u.x(), u.y(), u.z(), 1000 * open, 1000 * arm.restWristOffset().x(), 1000 * arm.restWristOffset().y(),
              1000 * arm.restWristOffset().z());
  EXPECT_EQ(arm.spec().name, "simulated arm");
  EXPECT_TRUE(arm.spec().forceOutput);
}

TEST(ArmInputDevice, TheOperatorPullsTheArmsHandToTheTarget) {
#ifdef HG_SANITIZED
  GTEST_SKIP() << "the arm is simulated at wall-clock speed; under a sanitizer it falls behind real time";
#endif
  freecad::ArmInputDevice arm(kRest, Vec3(0, 1, 0));  // turned: targets and fingertips convert
  const device::ArmPose rest = arm.restPose();
  const Vec3 move(0.03, -0.02, -0.04);
  const device::HandTarget target = shifted(rest, move);
  const device::DeviceSample s = drive(arm, target, 1.5);
  const double ei = (s.hand.index - target.index).norm(), et = (s.hand.thumb - target.thumb).norm();
  const Vec3 centre = 0.5 * (s.hand.index + s.hand.thumb), want = 0.5 * (target.index + target.thumb);
  std::printf("after 1.5 s: index %.1f mm, thumb %.1f mm, grip centre %.1f mm from the target (moved %.1f mm)\n",
              1000 * ei, 1000 * et, 1000 * (centre - want).norm(), 1000 * move.norm());
  EXPECT_LT((centre - want).norm(), 0.005);  // measured 0.0 mm
  EXPECT_LT(ei, 0.005);  // measured 0.1 mm
  EXPECT_LT(et, 0.005);
  EXPECT_GT(arm.simTime(), 1.0);
}

TEST(ArmInputDevice, SilentUntilFedAndAfterTheHoldTime) {
#ifdef HG_SANITIZED
  GTEST_SKIP() << "the arm is simulated at wall-clock speed; under a sanitizer it falls behind real time";
#endif
  // The hold time is long against a busy machine's stalls (CI once stalled this thread past
  // a 50 ms hold between feeding and reading); the wait for silence is past it by a margin,
  // and a sleep never ends early, so neither expectation depends on the machine's load.
  constexpr double kHold_s = 1.0;
  freecad::ArmInputDevice arm(kRest, Vec3::Zero(), kHold_s);
  device::DeviceSample sample;
  EXPECT_FALSE(arm.read(sample));  // no target yet
  std::this_thread::sleep_for(2ms);
  arm.setTarget(shifted(arm.restPose(), Vec3::Zero()));
  EXPECT_TRUE(arm.read(sample));
  std::this_thread::sleep_for(2ms);
  EXPECT_TRUE(arm.read(sample));  // held
  std::this_thread::sleep_for(std::chrono::duration<double>(kHold_s + 0.1));
  EXPECT_FALSE(arm.read(sample));  // not fed for longer than the hold time
  arm.setTarget(shifted(arm.restPose(), Vec3::Zero()));
  std::this_thread::sleep_for(2ms);
  EXPECT_TRUE(arm.read(sample));
  arm.setSilent(true);
  std::this_thread::sleep_for(2ms);
  EXPECT_FALSE(arm.read(sample));
  arm.setSilent(false);
  std::this_thread::sleep_for(2ms);
  EXPECT_TRUE(arm.read(sample));
}

TEST(ArmInputDevice, RejectsBadArguments) {
  EXPECT_THROW(freecad::ArmInputDevice(kRest, Vec3::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(freecad::ArmInputDevice(Vec3(std::nan(""), 0, 0)), std::invalid_argument);
}

TEST(ArmInputDevice, ReadAndWriteAllocateNothing) {
  freecad::ArmInputDevice arm(kRest);
  const device::HandTarget target = shifted(arm.restPose(), Vec3(0, 0, -0.02));
  drive(arm, target, 0.05);  // warm up
  device::DeviceCommand command;
  command.f_index = Vec3(0, 0, 1);
  command.f_thumb = Vec3(0, 0, -1);
  command.f_grasp = 2;
  device::DeviceSample sample;
  const long before = test::allocations();
  for (int i = 0; i < 500; ++i) {
    arm.read(sample);
    arm.write(command);
    std::this_thread::sleep_for(200us);
  }
  const long allocated = test::allocations() - before;
  EXPECT_EQ(allocated, 0);
}

namespace {
// Feeds a pinched target (fingertips 5 mm apart at the resting grip centre) while writing a
// grasp command (grip force f_grasp, eq 25: it holds the fingers apart as a part would).
// Returns the largest turn of the arm's wrist from where it was after the first 0.2 s (deg).
double squeezeTurn_deg(double f_grasp, double seconds) {
  freecad::ArmInputDevice arm(kRest);
  const device::ArmPose r = arm.restPose();
  const Vec3 c = 0.5 * (r.index + r.thumb), u = arm.gripAxis();
  const device::HandTarget pinched{c + 0.0025 * u, c - 0.0025 * u, r.wrist};
  device::DeviceCommand grasp;
  grasp.f_grasp = f_grasp;
  device::DeviceSample s;
  drive(arm, shifted(r, Vec3::Zero()), 0.2);
  arm.read(s);
  const Mat3 start = s.hand.wristRotation;
  double turn = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (int i = 0; std::chrono::steady_clock::now() < end; ++i) {
    if (i % 10 == 0) arm.setTarget(pinched);
    arm.read(s);
    arm.write(grasp);
    turn = std::max(turn, Eigen::AngleAxisd(s.hand.wristRotation * start.transpose()).angle());
    std::this_thread::sleep_for(1ms);
  }
  return turn * 180 / M_PI;
}
}  // namespace

// Holding a part (the command carries a grip force) the operator keeps the hand's
// orientation from the grasp's start; without a grasp it is free and the squeezing
// fingers turn the hand.
TEST(ArmInputDevice, HoldsTheHandsOrientationWhileGrasping) {
  const double held = squeezeTurn_deg(5.0, 1.0), free = squeezeTurn_deg(0.0, 1.0);
  std::printf("arm device: wrist turned %.1f deg grasping, %.1f deg not grasping\n", held, free);
  EXPECT_LT(held, 5.0);
  EXPECT_GT(free, 2 * held);
}
