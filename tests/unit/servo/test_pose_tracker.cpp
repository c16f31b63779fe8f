// A reader rebuilds every part's pose from snapshots that carry only what moves.
#include "hapticgrasp/servo/pose_tracker.hpp"

#include <gtest/gtest.h>

namespace hg::servo {
namespace {

grasp::PartPose at(double x) {
  grasp::PartPose p;
  p.position = Vec3(x, 0, 0);
  return p;
}

void putDown(ServoSnapshot& s, int part, double x) {
  s.moveLog[s.moveCount % ServoSnapshot::kMoveLog] = {part, at(x)};
  ++s.moveCount;
}

TEST(PoseTracker, MovingPartsPutDownsAndResets) {
  PoseTracker t({at(0), at(1), at(2)});
  ServoSnapshot s;
  s.movingCount = 1;
  s.moving[0] = {1, at(5)};
  EXPECT_TRUE(t.update(s));
  EXPECT_EQ(t.pose(1).position.x(), 5);
  EXPECT_EQ(t.pose(0).position.x(), 0);
  s.movingCount = 0;
  putDown(s, 1, 6);
  putDown(s, 2, 7);
  EXPECT_TRUE(t.update(s));
  EXPECT_EQ(t.pose(1).position.x(), 6);
  EXPECT_EQ(t.pose(2).position.x(), 7);
  EXPECT_TRUE(t.update(s));  // nothing new: nothing changes
  EXPECT_EQ(t.pose(2).position.x(), 7);
  putDown(s, -1, 0);  // a reset: every part back
  putDown(s, 0, 9);   // then part 0 moved
  EXPECT_TRUE(t.update(s));
  EXPECT_EQ(t.pose(0).position.x(), 9);
  EXPECT_EQ(t.pose(1).position.x(), 1);
  EXPECT_EQ(t.pose(2).position.x(), 2);
}

TEST(PoseTracker, SaysWhenPutDownsWereLost) {
  PoseTracker t({at(0), at(1)});
  ServoSnapshot s;
  putDown(s, 0, 3);
  for (int i = 0; i < ServoSnapshot::kMoveLog; ++i) putDown(s, 1, 10 + i);
  EXPECT_FALSE(t.update(s));  // part 0's put-down fell out of the log
  EXPECT_EQ(t.pose(1).position.x(), 10 + ServoSnapshot::kMoveLog - 1);
  EXPECT_EQ(t.pose(0).position.x(), 0);
  putDown(s, 0, 4);
  EXPECT_TRUE(t.update(s));
  EXPECT_EQ(t.pose(0).position.x(), 4);
}

}  // namespace
}  // namespace hg::servo
