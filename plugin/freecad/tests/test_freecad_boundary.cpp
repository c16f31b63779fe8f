// The FreeCAD boundary: mm <-> m and Placement <-> PartPose, converted once.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "freecad_boundary.hpp"

using namespace hg;
using namespace hg::freecad;

TEST(FreeCadBoundary, MillimetresToMetresAndBack) {
  EXPECT_DOUBLE_EQ(toMetres(1000.0), 1.0);
  EXPECT_DOUBLE_EQ(toMillimetres(0.25), 250.0);
  const Vec3 m = toMetres(std::array<double, 3>{400, -50, 12.5});
  EXPECT_TRUE(m.isApprox(Vec3(0.4, -0.05, 0.0125)));
  const auto mm = toMillimetres(m);
  EXPECT_NEAR(mm[0], 400, 1e-12);
  EXPECT_NEAR(mm[1], -50, 1e-12);
  EXPECT_NEAR(mm[2], 12.5, 1e-12);
}

TEST(FreeCadBoundary, PlacementToPoseUsesFreeCadsQuaternionOrder) {
  // FreeCAD: Rotation(Vector(0,0,1), 90).Q == (0, 0, sin 45deg, cos 45deg).
  const double s = std::sin(std::numbers::pi / 4), c = std::cos(std::numbers::pi / 4);
  const grasp::PartPose pose = toPose({{10, 20, 30}, {0, 0, s, c}});
  EXPECT_TRUE(pose.position.isApprox(Vec3(0.01, 0.02, 0.03)));
  EXPECT_TRUE((pose.rotation * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-12));  // x -> y
  EXPECT_TRUE(pose.pointToAbsolute(Vec3(0.001, 0, 0)).isApprox(Vec3(0.01, 0.021, 0.03), 1e-12));
}

TEST(FreeCadBoundary, RoundTripAndNormalisation) {
  const Placement in{{-123.5, 7, 1e4}, {0.2, -0.4, 0.1, 0.8}};
  const Placement out = toPlacement(toPose(in));
  const double n = std::sqrt(0.04 + 0.16 + 0.01 + 0.64);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(out.base_mm[i], in.base_mm[i], 1e-9);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(out.quaternion[i], in.quaternion[i] / n, 1e-12);
  // -q is the same rotation; the boundary hands out w >= 0.
  const Placement neg = toPlacement(toPose({{0, 0, 0}, {-0.2, 0.4, -0.1, -0.8}}));
  EXPECT_GT(neg.quaternion[3], 0);
  EXPECT_NEAR(neg.quaternion[0], 0.2 / n, 1e-12);
}

TEST(FreeCadBoundary, RejectsBadPlacements) {
  EXPECT_THROW(toPose({{0, 0, 0}, {0, 0, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(toPose({{0, 0, 0}, {NAN, 0, 0, 1}}), std::invalid_argument);
  EXPECT_THROW(toPose({{INFINITY, 0, 0}, {0, 0, 0, 1}}), std::invalid_argument);
}

TEST(FreeCadBoundary, HandKeysInMillimetres) {
  HandKeyMm key;
  key.t = 0.5;
  key.index_mm = {70, 0, 0};
  key.thumb_mm = {-70, 0, 0};
  key.wrist_mm = {0, 0, 100};
  key.shift_mm = {0, 100, 50};
  key.turn = 0.25;
  const grasp::HandKey k = toHandKey(key);
  EXPECT_EQ(k.t, 0.5);
  EXPECT_TRUE(k.index.isApprox(Vec3(0.07, 0, 0)));
  EXPECT_TRUE(k.thumb.isApprox(Vec3(-0.07, 0, 0)));
  EXPECT_TRUE(k.wrist.isApprox(Vec3(0, 0, 0.1)));
  EXPECT_TRUE(k.shift.isApprox(Vec3(0, 0.1, 0.05)));
  EXPECT_EQ(k.turn, 0.25);
}
