// between(): the hand part of the way from one sample to the next, what the servo feeds a
// grasp method across a late tick.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hapticgrasp/grasp/hand_sample.hpp"

namespace hg::grasp {
namespace {

HandSample sample(double t, const Vec3& shift, double yaw) {
  HandSample h;
  h.t = t;
  h.index = Vec3(0.05, 0, 0) + shift;
  h.thumb = Vec3(-0.05, 0, 0) + shift;
  h.wrist = Vec3(0, 0, 0.1) + shift;
  for (int k = 2; k < HandSample::kMaxFingertips; ++k) h.fingertip(k) = Vec3(0.01 * k, 0.02, 0) + shift;
  h.wristRotation = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  return h;
}

TEST(HandSample, BetweenTwoSamplesMovesStraightAndTurnsTheShortWay) {
  const HandSample a = sample(1.0, Vec3::Zero(), 0.0), b = sample(1.2, Vec3(0, 0.1, 0.04), std::numbers::pi / 2);
  const HandSample h = between(a, b, 0.25);
  EXPECT_DOUBLE_EQ(h.t, 1.05);
  EXPECT_TRUE(h.index.isApprox(Vec3(0.05, 0.025, 0.01), 1e-15));
  EXPECT_TRUE(h.thumb.isApprox(Vec3(-0.05, 0.025, 0.01), 1e-15));
  EXPECT_TRUE(h.wrist.isApprox(Vec3(0, 0.025, 0.11), 1e-15));
  for (int k = 2; k < HandSample::kMaxFingertips; ++k)
    EXPECT_TRUE(h.fingertip(k).isApprox(Vec3(0.01 * k, 0.045, 0.01), 1e-15)) << k;
  // A quarter of a quarter turn about z, still a rotation.
  const Eigen::AngleAxisd turn(h.wristRotation);
  EXPECT_NEAR(turn.angle(), std::numbers::pi / 8, 1e-12);
  EXPECT_NEAR(turn.axis().z(), 1.0, 1e-12);
  EXPECT_NEAR((h.wristRotation * h.wristRotation.transpose() - Mat3::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(h.wristRotation.determinant(), 1.0, 1e-12);
}

TEST(HandSample, BetweenAtItsEndsIsEachSample) {
  const HandSample a = sample(0.0, Vec3(0.3, 0, 0), -1.0), b = sample(0.5, Vec3(0, 0.2, 0), 2.0);
  for (const auto& [f, end] : {std::pair{0.0, a}, std::pair{1.0, b}}) {
    const HandSample h = between(a, b, f);
    EXPECT_DOUBLE_EQ(h.t, end.t);
    EXPECT_TRUE(h.index.isApprox(end.index, 1e-15));
    EXPECT_TRUE(h.extra[2].isApprox(end.extra[2], 1e-15));
    EXPECT_TRUE(h.wristRotation.isApprox(end.wristRotation, 1e-12)) << f;
  }
}

TEST(HandSample, TurnsThroughTheShorterArcAcrossHalfATurn) {
  // From +170° to -170° about z is 20° through 180°, not 340° back through 0°.
  const double deg = std::numbers::pi / 180;
  const HandSample h = between(sample(0, Vec3::Zero(), 170 * deg), sample(1, Vec3::Zero(), -170 * deg), 0.5);
  const Vec3 x = h.wristRotation * Vec3::UnitX();
  EXPECT_NEAR(x.x(), -1.0, 1e-12);  // at 180°; the long way round would be at 0°
}

}  // namespace
}  // namespace hg::grasp
