// The broad phase answers exactly what a scan of every box answers, before and after parts
// move, and never allocates doing it.
#include "hapticgrasp/scene/broad_phase.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "alloc_counter.hpp"

namespace hg::grasp {
namespace {

using geometry::Aabb;

Aabb randomBox(std::mt19937& rng, double extent) {
  std::uniform_real_distribution<double> at(-extent, extent), size(0.001, 0.05 * extent);
  const Vec3 c(at(rng), at(rng), at(rng));
  const Vec3 h(size(rng), size(rng), size(rng));
  return {c - h, c + h};
}

std::vector<int> scan(const std::vector<Aabb>& boxes, const Vec3& x) {
  std::vector<int> hits;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (boxes[i].contains(x)) hits.push_back(static_cast<int>(i));
  return hits;
}

std::vector<int> ask(const BroadPhase& bp, const Vec3& x) {
  std::vector<int> out(bp.size() + 1);
  out.resize(bp.query(x, out));
  std::sort(out.begin(), out.end());
  return out;
}

// Points inside some box half the time: a random box's random point, else anywhere.
Vec3 probe(std::mt19937& rng, const std::vector<Aabb>& boxes, double extent) {
  std::uniform_real_distribution<double> u(0, 1), at(-extent, extent);
  if (u(rng) < 0.5) {
    const Aabb& b = boxes[std::uniform_int_distribution<std::size_t>(0, boxes.size() - 1)(rng)];
    return b.min + (b.max - b.min).cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
  }
  return {at(rng), at(rng), at(rng)};
}

TEST(BroadPhase, FindsWhatAScanOfEveryBoxFinds) {
  std::mt19937 rng(7);
  for (const int n : {1, 2, 3, 17, 1000}) {
    std::vector<Aabb> boxes;
    for (int i = 0; i < n; ++i) boxes.push_back(randomBox(rng, 1.0));
    const BroadPhase bp(boxes);
    ASSERT_EQ(bp.size(), boxes.size());
    int hits = 0;
    for (int k = 0; k < 2000; ++k) {
      const Vec3 x = probe(rng, boxes, 1.0);
      const std::vector<int> expected = scan(boxes, x);
      hits += !expected.empty();
      ASSERT_EQ(ask(bp, x), expected) << n << " boxes, probe " << k;
    }
    EXPECT_GT(hits, 500) << "the probes must land in boxes";
  }
}

TEST(BroadPhase, AMovedPartIsFoundWhereItIsNowAndNotWhereItWas) {
  std::mt19937 rng(11);
  std::vector<Aabb> boxes;
  for (int i = 0; i < 500; ++i) boxes.push_back(randomBox(rng, 1.0));
  BroadPhase bp(boxes);
  const Vec3 far(5, 5, 5);  // outside every box as built
  ASSERT_TRUE(ask(bp, far).empty());
  const Vec3 before = boxes[42].centre();
  boxes[42] = {far - Vec3::Constant(0.01), far + Vec3::Constant(0.01)};
  bp.update(42, boxes[42]);
  EXPECT_EQ(ask(bp, far), std::vector<int>{42});
  EXPECT_EQ(ask(bp, before), scan(boxes, before));
  // Many moves, then the same answers as a scan.
  for (int m = 0; m < 300; ++m) {
    const std::size_t i = std::uniform_int_distribution<std::size_t>(0, boxes.size() - 1)(rng);
    boxes[i] = randomBox(rng, 3.0);
    bp.update(i, boxes[i]);
  }
  for (int k = 0; k < 2000; ++k) {
    const Vec3 x = probe(rng, boxes, 3.0);
    ASSERT_EQ(ask(bp, x), scan(boxes, x)) << "probe " << k;
  }
}

TEST(BroadPhase, SaysHowManyItHoldsWhenTheBufferIsShort) {
  std::vector<Aabb> nested;
  for (int i = 1; i <= 10; ++i) nested.push_back({Vec3::Constant(-i), Vec3::Constant(i)});
  const BroadPhase bp(nested);
  int out[4] = {-1, -1, -1, -1};
  EXPECT_EQ(bp.query(Vec3::Zero(), out), 10u);
  for (const int i : out) EXPECT_TRUE(i >= 0 && i < 10);
  EXPECT_EQ(bp.query(Vec3::Constant(9.5), out), 1u);
  EXPECT_EQ(out[0], 9);
}

TEST(BroadPhase, EmptyBoxesAndEmptySetsHoldNothing) {
  const BroadPhase none;
  int out[2];
  EXPECT_EQ(none.query(Vec3::Zero(), out), 0u);
  const std::vector<Aabb> boxes{Aabb{}, {Vec3::Constant(-1), Vec3::Constant(1)}, Aabb{}};
  const BroadPhase bp(boxes);
  EXPECT_EQ(ask(bp, Vec3::Zero()), std::vector<int>{1});
  EXPECT_TRUE(ask(bp, Vec3::Constant(2)).empty());
}

TEST(BroadPhase, FindsTheBoxesABoxOverlapsAsAScanDoes) {
  std::mt19937 rng(4);
  std::vector<Aabb> boxes;
  for (int i = 0; i < 500; ++i) boxes.push_back(randomBox(rng, 10.0));
  BroadPhase bp(boxes);
  for (int k = 0; k < 200; ++k) {
    const Aabb box = randomBox(rng, 10.0);
    std::vector<int> expected;
    for (std::size_t i = 0; i < boxes.size(); ++i)
      if ((box.min.array() <= boxes[i].max.array()).all() && (boxes[i].min.array() <= box.max.array()).all())
        expected.push_back(static_cast<int>(i));
    std::vector<int> out(boxes.size());
    out.resize(bp.overlapping(box, out));
    std::sort(out.begin(), out.end());
    ASSERT_EQ(out, expected);
  }
  int one[1];
  EXPECT_EQ(bp.overlapping(Aabb{Vec3::Constant(-20), Vec3::Constant(20)}, one), boxes.size());
  EXPECT_EQ(bp.overlapping(Aabb{}, one), 0u);
}

TEST(BroadPhase, QueryAndUpdateAllocateNothing) {
  std::mt19937 rng(3);
  std::vector<Aabb> boxes;
  for (int i = 0; i < 10000; ++i) boxes.push_back(randomBox(rng, 10.0));
  BroadPhase bp(boxes);
  int out[16];
  const long before = test::allocations();
  std::size_t found = 0;
  for (int k = 0; k < 1000; ++k) {
    found += bp.query(probe(rng, boxes, 10.0), out);
    bp.update(static_cast<std::size_t>(k), randomBox(rng, 10.0));
  }
  EXPECT_EQ(test::allocations() - before, 0);
  EXPECT_GT(found, 0u);
}

}  // namespace
}  // namespace hg::grasp
