#include "hapticgrasp/device/fault_injecting_device.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <random>

#include "hapticgrasp/servo/servo_bench.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"

namespace hg::device {
namespace {

using ::testing::HasSubstr;

constexpr double kRate = 2000, kT = 1 / kRate;

// A hand whose index fingertip rests 2 mm deep in the top of the bench's cylinder (axis along
// y through (0.4, 0, 0.3), radius 0.05): a steady contact force, so zero forces mean the loop
// cut them. Counts what reaches it.
class PressingHand : public Device {
 public:
  PressingHand() {
    spec_.name = "pressing hand";
    spec_.timeout_s = 0.05;
    spec_.maxForce_N = 10;
  }
  const DeviceSpec& spec() const noexcept override { return spec_; }
  bool read(DeviceSample& s) noexcept override {
    ++reads;
    s.hand.index = Vec3(0.4, 0.0, 0.3 + 0.05 - 0.002);
    s.hand.thumb = Vec3(0.4, 0.0, 0.6);
    s.hand.wrist = Vec3(0.45, 0.0, 0.6);
    return true;
  }
  void write(const DeviceCommand& c) noexcept override {
    ++writes;
    lastForce = c.f_index.norm();
  }
  long reads = 0, writes = 0;
  double lastForce = 0;

 private:
  DeviceSpec spec_;
};

struct Rig {
  explicit Rig(std::vector<Fault> schedule) {
    hand = std::make_shared<PressingHand>();
    const double ramp = servo::ServoConfig{}.watchdogRamp_s + 4 * kT;
    faults = std::make_shared<FaultInjectingDevice>(hand, std::move(schedule), kRate, ramp, 7, WanderAmplitude{Vec3::Zero()},
                                                    [this] { return clock; });
    servo::ServoConfig config;
    config.rate_hz = kRate;
    config.realtime = false;
    loop = std::make_unique<servo::ServoLoop>(faults, servo::benchScene(), grasp::GraspParameters{}, config);
  }
  // Ticks the loop on this thread until `until_s`; returns the index force seen at the end.
  double runUntil(double until_s) {
    for (; clock < until_s; clock += kT) loop->step(clock, kT);
    return hand->lastForce;
  }
  double clock = 0;
  std::shared_ptr<PressingHand> hand;
  std::shared_ptr<FaultInjectingDevice> faults;
  std::unique_ptr<servo::ServoLoop> loop;
};

int k(FaultKind kind) { return static_cast<int>(kind); }

TEST(FaultInjectingDevice, SilenceIsHandledWhenTheLoopCutsTheForces) {
  Rig rig({{FaultKind::Silence, 0.3, 0.2}});
  EXPECT_GT(rig.runUntil(0.29), 0.1);  // pressing before the fault
  EXPECT_EQ(rig.runUntil(0.45), 0.0);  // the watchdog tripped and ramped
  EXPECT_GT(rig.runUntil(1.0), 0.1);   // and let go once samples came back
  const FaultReport r = rig.faults->report();
  EXPECT_EQ(r.injected[k(FaultKind::Silence)], 1u);
  EXPECT_EQ(r.handled[k(FaultKind::Silence)], 1u);
  EXPECT_EQ(r.nanOutputs, 0u);
}

TEST(FaultInjectingDevice, NonFiniteSamplesAreHandledAndNeverReachTheOutput) {
  Rig rig({{FaultKind::NaNSample, 0.2, 0.05}, {FaultKind::InfSample, 0.5, 0.05}});
  rig.runUntil(1.0);
  const FaultReport r = rig.faults->report();
  EXPECT_EQ(r.injected[k(FaultKind::NaNSample)], 1u);
  EXPECT_EQ(r.handled[k(FaultKind::NaNSample)], 1u);
  EXPECT_EQ(r.handled[k(FaultKind::InfSample)], 1u);
  EXPECT_EQ(r.nanOutputs, 0u);
  EXPECT_EQ(r.unboundedOutputs, 0u);
}

// Drives the device by hand as a (misbehaving) loop would: read, then write what `command`
// gives for the tick's time, until `until_s`; returns the verdicts.
template <typename Command>
FaultReport driveByHand(std::vector<Fault> schedule, double until_s, Command command) {
  double clock = 0;
  FaultInjectingDevice faults(std::make_shared<PressingHand>(), std::move(schedule), kRate, 0.015, 1,
                              WanderAmplitude{Vec3::Zero()}, [&] { return clock; });
  DeviceSample s;
  for (; clock < until_s; clock += kT) {
    faults.read(s);
    faults.write(command(clock));
  }
  return faults.report();
}

TEST(FaultInjectingDevice, ALoopThatKeepsPushingThroughSilenceIsCaught) {
  DeviceCommand pushing;
  pushing.f_index = Vec3(0, 0, 1);
  // Never zeroed: not what the loop does.
  const FaultReport r = driveByHand({{FaultKind::Silence, 0.1, 0.2}}, 0.5, [&](double) { return pushing; });
  EXPECT_EQ(r.injected[k(FaultKind::Silence)], 1u);
  EXPECT_EQ(r.handled[k(FaultKind::Silence)], 0u);
  ASSERT_EQ(r.unhandled.size(), 1u);
  EXPECT_EQ(r.unhandled[0].fault.kind, FaultKind::Silence);
  EXPECT_THAT(r.unhandled[0].why, HasSubstr("forces not zero"));
}

TEST(FaultInjectingDevice, ALoopThatDoesNotRunWhereForcesMustBeZeroFailsTheFaultAndSaysHowLongItWasAway) {
  // Zero forces once the NaN samples come, but no tick from 5 ms into the fault to past
  // its end: nothing was zeroed where it had to be.
  double clock = 0;
  FaultInjectingDevice faults(std::make_shared<PressingHand>(), {{FaultKind::NaNSample, 0.1, 0.05}}, kRate, 0.015, 1,
                              WanderAmplitude{Vec3::Zero()}, [&] { return clock; });
  DeviceSample s;
  for (; clock < 0.3; clock += kT) {
    if (clock > 0.105 && clock < 0.16) continue;
    faults.read(s);
    faults.write(DeviceCommand{});
  }
  const FaultReport r = faults.report();
  EXPECT_EQ(r.handled[k(FaultKind::NaNSample)], 0u);
  ASSERT_EQ(r.unhandled.size(), 1u);
  EXPECT_THAT(r.unhandled[0].why, HasSubstr("no command in its last 35.0 ms"));
  EXPECT_THAT(r.unhandled[0].why, HasSubstr("longest gap 45.5 ms"));
}

TEST(FaultInjectingDevice, EveryHandledFaultLeavesNothingInTheUnhandledList) {
  const FaultReport r = driveByHand({{FaultKind::NaNSample, 0.1, 0.05}, {FaultKind::Silence, 0.2, 0.3}}, 0.7,
                                    [](double) { return DeviceCommand{}; });
  EXPECT_EQ(r.totalHandled(), 2u);
  EXPECT_TRUE(r.unhandled.empty());
}

TEST(FaultInjectingDevice, ANonFiniteCommandIsCountedAndFailsTheFaultUnderWay) {
  const FaultReport r = driveByHand({{FaultKind::Stall, 0.1, 0.001}}, 0.3, [](double t) {
    DeviceCommand bad;
    bad.f_thumb.x() = t > 0.1 && t < 0.102 ? std::nan("") : 0.0;
    return bad;
  });
  EXPECT_EQ(r.nanOutputs, 4u);
  EXPECT_EQ(r.injected[k(FaultKind::Stall)], 1u);
  EXPECT_EQ(r.handled[k(FaultKind::Stall)], 0u);
  ASSERT_EQ(r.unhandled.size(), 1u);
  EXPECT_THAT(r.unhandled[0].why, HasSubstr("beyond the device's spec"));
}

TEST(FaultInjectingDevice, AnUnpluggedDeviceIsNeitherReadNorWrittenUntilItIsBack) {
  Rig rig({{FaultKind::Unplug, 0.2, 0.5}});
  rig.runUntil(0.25);
  const long reads = rig.hand->reads, writes = rig.hand->writes;
  rig.runUntil(0.65);
  EXPECT_EQ(rig.hand->reads, reads);
  EXPECT_EQ(rig.hand->writes, writes);
  rig.runUntil(1.2);
  EXPECT_GT(rig.hand->writes, writes);
  const FaultReport r = rig.faults->report();
  EXPECT_EQ(r.handled[k(FaultKind::Unplug)], 1u);
  EXPECT_GT(r.writesDropped, 800u);
}

TEST(FaultInjectingDevice, AStallBlocksOneReadForItsDuration) {
  Rig rig({{FaultKind::Stall, 0.1, 0.02}});
  rig.runUntil(0.1);
  const auto start = std::chrono::steady_clock::now();
  rig.runUntil(0.1 + 2 * kT);
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.02);
  rig.runUntil(0.3);
  const FaultReport r = rig.faults->report();
  EXPECT_EQ(r.injected[k(FaultKind::Stall)], 1u);
  EXPECT_EQ(r.handled[k(FaultKind::Stall)], 1u);
}

TEST(FaultInjectingDevice, AModelSwapMarkedFromOutsideIsJudgedByWhatFollows) {
  Rig rig({});
  rig.runUntil(0.1);
  ASSERT_TRUE(rig.faults->markExternal(FaultKind::ModelSwap));
  EXPECT_EQ(rig.faults->report().handled[k(FaultKind::ModelSwap)], 0u);  // nothing written since
  rig.runUntil(0.2);
  const FaultReport r = rig.faults->report();
  EXPECT_EQ(r.injected[k(FaultKind::ModelSwap)], 1u);
  EXPECT_EQ(r.handled[k(FaultKind::ModelSwap)], 1u);
}

TEST(FaultInjectingDevice, RandomFaultsAreApartSortedInRangeAndTakeEveryKindInTurn) {
  std::mt19937_64 random(3);
  const std::vector<Fault> faults = randomFaults(600, 30, random, 2);
  ASSERT_GT(faults.size(), 150u);
  EXPECT_EQ(faults[0].kind, FaultKind::InfSample);
  for (std::size_t i = 0; i < faults.size(); ++i) {
    const Fault& f = faults[i];
    EXPECT_EQ(f.kind, static_cast<FaultKind>((i + 2) % 5));
    EXPECT_GE(f.start_s, 1.0);
    EXPECT_LE(f.start_s + f.duration_s, 600);
    if (i > 0) {
      EXPECT_GE(f.start_s, faults[i - 1].start_s + faults[i - 1].duration_s + 0.5);
    }
    const auto [lo, hi] = f.kind == FaultKind::Silence  ? std::pair(0.1, 0.5)
                          : f.kind == FaultKind::Stall  ? std::pair(0.005, 0.05)
                          : f.kind == FaultKind::Unplug ? std::pair(0.5, 2.0)
                                                        : std::pair(0.02, 0.1);
    EXPECT_GE(f.duration_s, lo);
    EXPECT_LE(f.duration_s, hi);
  }
  EXPECT_THROW(FaultInjectingDevice(std::make_shared<PressingHand>(), {faults[1], faults[0]}, kRate, 0.015),
               std::invalid_argument);
}

TEST(FaultInjectingDevice, TheWanderMovesTheWholeHandTogetherWithinItsAmplitude) {
  auto hand = std::make_shared<PressingHand>();
  double clock = 0;
  const WanderAmplitude wander{Vec3(0.015, 0.004, 0.01)};
  FaultInjectingDevice faults(hand, {}, kRate, 0.015, 11, wander, [&] { return clock; });
  DeviceSample plain, moved;
  hand->read(plain);
  double largest = 0;
  for (; clock < 20; clock += 0.01) {
    ASSERT_TRUE(faults.read(moved));
    const Vec3 offset = moved.hand.index - plain.hand.index;
    EXPECT_NEAR((moved.hand.thumb - plain.hand.thumb - offset).norm(), 0, 1e-12);
    EXPECT_NEAR((moved.hand.wrist - plain.hand.wrist - offset).norm(), 0, 1e-12);
    for (int a = 0; a < 3; ++a) EXPECT_LE(std::abs(offset[a]), wander.amplitude_m[a] + 1e-12);
    largest = std::max(largest, offset.x());
  }
  EXPECT_GT(largest, 0.3 * wander.amplitude_m.x());  // it does wander
}

}  // namespace
}  // namespace hg::device
