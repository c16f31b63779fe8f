// The record ring between the servo thread and the recorder's writer: order, capacity,
// drops counted, and a producer and consumer on two threads losing and reordering nothing.
#include <gtest/gtest.h>

#include <thread>

#include "hapticgrasp/servo/tick_record.hpp"

namespace hg::servo {
namespace {

TEST(TickRecordRing, CapacityIsAPowerOfTwoAtLeastAsked) {
  EXPECT_EQ(TickRecordRing(0).capacity(), 2u);
  EXPECT_EQ(TickRecordRing(5).capacity(), 8u);
  EXPECT_EQ(TickRecordRing(4096).capacity(), 4096u);
}

TEST(TickRecordRing, KeepsOrderAndCountsWhatItDrops) {
  TickRecordRing ring(4);
  TickRecord r;
  for (std::uint64_t k = 1; k <= 6; ++k) {
    r.tick = k;
    EXPECT_EQ(ring.push(r), k <= 4) << k;
  }
  EXPECT_EQ(ring.pushed(), 4u);
  EXPECT_EQ(ring.dropped(), 2u);
  EXPECT_EQ(ring.size(), 4u);
  for (std::uint64_t k = 1; k <= 4; ++k) {
    ASSERT_TRUE(ring.pop(r));
    EXPECT_EQ(r.tick, k);
  }
  EXPECT_FALSE(ring.pop(r));
  r.tick = 7;
  EXPECT_TRUE(ring.push(r));  // room again after the reads
}

TEST(TickRecordRing, TwoThreadsLoseAndReorderNothing) {
  TickRecordRing ring(64);
  constexpr std::uint64_t kCount = 200000;
  std::thread producer([&] {
    TickRecord r;
    for (std::uint64_t k = 1; k <= kCount; ++k) {
      r.tick = k;
      r.time_s = static_cast<double>(k);
      while (!ring.push(r)) std::this_thread::yield();
    }
  });
  std::uint64_t expected = 1, bad = 0;
  TickRecord r;
  while (expected <= kCount) {
    if (!ring.pop(r)) continue;
    bad += r.tick != expected || r.time_s != static_cast<double>(expected);
    ++expected;
  }
  producer.join();
  EXPECT_EQ(bad, 0u);
  // The producer retried instead of pushing into a full ring, each retry counted as a drop.
  EXPECT_EQ(ring.pushed(), kCount);
}

}  // namespace
}  // namespace hg::servo
