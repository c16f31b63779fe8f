// The hand the front end feeds: read by the servo thread, silent when not fed.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "hand_input_device.hpp"

using namespace hg;
using namespace std::chrono_literals;

TEST(HandInputDevice, SilentUntilFedAndAfterTheHoldTime) {
  // A hold long against a busy machine's stalls, and a wait past it: a sleep never ends
  // early, so neither expectation depends on the machine's load.
  constexpr double kHold_s = 1.0;
  freecad::HandInputDevice device(kHold_s);
  device::DeviceSample sample;
  EXPECT_FALSE(device.read(sample));
  grasp::HandSample hand;
  hand.index = Vec3(0.1, 0, 0);
  hand.thumb = Vec3(-0.1, 0, 0);
  device.setHand(hand);
  ASSERT_TRUE(device.read(sample));
  EXPECT_TRUE(sample.hand.index.isApprox(hand.index));
  EXPECT_TRUE(sample.hand.thumb.isApprox(hand.thumb));
  EXPECT_TRUE(device.read(sample));  // held: the servo reads it every tick
  std::this_thread::sleep_for(std::chrono::duration<double>(kHold_s + 0.1));
  EXPECT_FALSE(device.read(sample));  // not fed for longer than the hold time
  device.setHand(hand);
  EXPECT_TRUE(device.read(sample));
  device.setSilent(true);
  EXPECT_FALSE(device.read(sample));
  device.setSilent(false);
  EXPECT_TRUE(device.read(sample));
}

TEST(HandInputDevice, RejectsABadHoldTime) {
  EXPECT_THROW(freecad::HandInputDevice(0.0), std::invalid_argument);
  EXPECT_THROW(freecad::HandInputDevice(-1.0), std::invalid_argument);
}

TEST(HandInputDevice, ConcurrentWriterAndReaderSeeWholeSamples) {
  freecad::HandInputDevice device(1.0);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int i = 0; i < 20000; ++i) {
      grasp::HandSample hand;
      hand.index = Vec3(i, i, i);
      hand.thumb = Vec3(-i, -i, -i);
      device.setHand(hand);
    }
    done = true;
  });
  long torn = 0, reads = 0;
  device::DeviceSample sample;
  while (!done.load()) {
    if (!device.read(sample)) continue;
    ++reads;
    if (!(sample.hand.thumb + sample.hand.index).isZero() || sample.hand.index.x() != sample.hand.index.z()) ++torn;
  }
  writer.join();
  EXPECT_EQ(torn, 0);
  std::printf("%ld consistent reads\n", reads);
}
