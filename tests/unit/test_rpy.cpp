// The first paper's RPY convention: eq 1 entry by entry, its direction (absolute ->
// object), the robust eq 21 (round trips everywhere, pitch +/-90 and yaw +/-180 degrees
// included), the printed eq 21's failure it replaces, and the rotation-vector helpers.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "hapticgrasp/math/rpy.hpp"

namespace hg::math {
namespace {

constexpr double kPi = std::numbers::pi;

// Eq 1 typed in again from the paper, element by element.
Mat3 printedEq1(double x, double y, double z) {
  const double cx = std::cos(x), cy = std::cos(y), cz = std::cos(z);
  const double sx = std::sin(x), sy = std::sin(y), sz = std::sin(z);
  Mat3 R;
  R(0, 0) = cy * cz;
  R(0, 1) = cx * sz + sx * sy * cz;
  R(0, 2) = sx * sz - cx * sy * cz;
  R(1, 0) = -cy * sz;
  R(1, 1) = cx * cz - sx * sy * sz;
  R(1, 2) = sx * cz + cx * sy * sz;
  R(2, 0) = sy;
  R(2, 1) = -sx * cy;
  R(2, 2) = cx * cy;
  return R;
}

Mat3 rotX(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }
Mat3 rotY(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }
Mat3 rotZ(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

std::vector<Vec3> randomRpy(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> full(-kPi, kPi), half(-kPi / 2, kPi / 2);
  std::vector<Vec3> out;
  for (int i = 0; i < n; ++i) out.emplace_back(full(rng), half(rng), full(rng));
  return out;
}

TEST(Rpy, Eq1EntryByEntry) {
  for (const Vec3& a : randomRpy(200, 1)) {
    const Mat3 R = paperRotation(a);
    EXPECT_LT((R - printedEq1(a.x(), a.y(), a.z())).cwiseAbs().maxCoeff(), 1e-15) << a.transpose();
    EXPECT_LT((R * R.transpose() - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
    // The pose rotation (object -> absolute) it is the transpose of: roll, then pitch, then
    // yaw about the moving axes.
    EXPECT_LT((R.transpose() - rotX(a.x()) * rotY(a.y()) * rotZ(a.z())).norm(), 1e-14);
  }
}

TEST(Rpy, Eq1MapsAbsoluteVectorsIntoTheObjectFrame) {
  // An object turned +90 deg about z: its x axis points along absolute y, so the absolute
  // vector y is the object's x (eq 2: x^o = R x^a).
  const Mat3 R = paperRotation(Vec3(0, 0, kPi / 2));
  EXPECT_LT((R * Vec3::UnitY() - Vec3::UnitX()).norm(), 1e-15);
  EXPECT_LT((R * Vec3::UnitX() + Vec3::UnitY()).norm(), 1e-15);
  // Pitch +90 deg about y: the object's z axis points along absolute -x... so absolute -x
  // is the object's z; roll about x likewise.
  EXPECT_LT((paperRotation(Vec3(0, kPi / 2, 0)) * Vec3(1, 0, 0) - Vec3(0, 0, 1)).norm(), 1e-15);
  EXPECT_LT((paperRotation(Vec3(kPi / 2, 0, 0)) * Vec3(0, 0, 1) - Vec3(0, 1, 0)).norm(), 1e-15);
}

TEST(Rpy, Eq21RoundTripsInsideItsRange) {
  for (const Vec3& a : randomRpy(2000, 2)) {
    const Vec3 b = paperRpy(paperRotation(a));
    EXPECT_LT((b - a).cwiseAbs().maxCoeff(), 1e-12) << a.transpose() << " -> " << b.transpose();
  }
}

TEST(Rpy, Eq21AtPitchPlusMinus90AndNear) {
  for (double pitch : {kPi / 2, -kPi / 2, kPi / 2 - 1e-9, -kPi / 2 + 1e-9, kPi / 2 - 1e-5, kPi / 2 + 1e-7}) {
    for (double roll : {-3.0, -1.0, 0.0, 0.4, 2.5, kPi}) {
      for (double yaw : {-kPi, -2.0, 0.0, 0.7, kPi / 2, kPi}) {
        const Mat3 R = paperRotation(Vec3(roll, pitch, yaw));
        const Vec3 a = paperRpy(R);
        ASSERT_TRUE(a.allFinite()) << roll << " " << pitch << " " << yaw;
        EXPECT_LE(std::abs(a.y()), kPi / 2 + 1e-15);
        // The angles are not unique at gimbal lock, the rotation is.
        EXPECT_LT((paperRotation(a) - R).cwiseAbs().maxCoeff(), 1e-9) << roll << " " << pitch << " " << yaw;
      }
    }
  }
  // Exactly at the lock (cos(pitch) = 0 exactly, which cos(pi/2) in doubles is not):
  // pitch comes out exactly, yaw is chosen 0 and roll carries the whole turn.
  for (double sy : {1.0, -1.0}) {
    const double x = 0.3, z = 0.5;
    Mat3 lock = printedEq1(x, 0, z);  // then overwrite the pitch terms with cy = 0, sy = +/-1
    const double cx = std::cos(x), sx = std::sin(x), cz = std::cos(z), sz = std::sin(z);
    lock << 0, cx * sz + sx * sy * cz, sx * sz - cx * sy * cz, 0, cx * cz - sx * sy * sz, sx * cz + cx * sy * sz, sy,
        0, 0;
    const Vec3 a = paperRpy(lock);
    EXPECT_DOUBLE_EQ(a.y(), sy * kPi / 2);
    EXPECT_EQ(a.z(), 0.0);
    EXPECT_NEAR(a.x(), sy > 0 ? x + z : x - z, 1e-15);
    EXPECT_LT((paperRotation(a) - lock).cwiseAbs().maxCoeff(), 1e-15);
  }
}

TEST(Rpy, Eq21AtYawPlusMinus180) {
  for (double yaw : {kPi, -kPi, kPi - 1e-12, -kPi + 1e-12}) {
    for (double roll : {-2.0, 0.0, 1.0}) {
      for (double pitch : {-1.2, 0.0, 0.9}) {
        const Mat3 R = paperRotation(Vec3(roll, pitch, yaw));
        const Vec3 a = paperRpy(R);
        EXPECT_LT((paperRotation(a) - R).cwiseAbs().maxCoeff(), 1e-12);
        EXPECT_NEAR(std::abs(wrapAngle(a.z() - yaw)), 0.0, 1e-9);  // +180 and -180 are one yaw
      }
    }
  }
}

TEST(Rpy, PrintedEq21FailsWhereTheRobustOneDoesNot) {
  // Away from trouble they agree.
  for (const Vec3& a : randomRpy(200, 3)) {
    if (std::abs(std::cos(a.z())) < 0.1) continue;
    EXPECT_LT((paperRpyAsPrinted(paperRotation(a)) - a).cwiseAbs().maxCoeff(), 1e-10);
  }
  // At yaw = 90 deg, R11 = cos(pitch) cos(yaw) is 0 (here it rounds to exactly 0), and the
  // printed form divides it by cos(atan2(-R21, 0)) = 6e-17: pitch comes out as 90 deg.
  Mat3 R = paperRotation(Vec3(0.2, 0.3, kPi / 2));
  ASSERT_LT(std::abs(R(0, 0)), 1e-16);
  R(0, 0) = 0;
  EXPECT_GT(std::abs(paperRpyAsPrinted(R).y() - 0.3), 1.0);
  EXPECT_LT((paperRpy(R) - Vec3(0.2, 0.3, kPi / 2)).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Rpy, WrapAngle) {
  EXPECT_DOUBLE_EQ(wrapAngle(0.5), 0.5);
  EXPECT_NEAR(wrapAngle(2 * kPi + 0.5), 0.5, 1e-15);
  EXPECT_NEAR(wrapAngle(-2 * kPi - 0.5), -0.5, 1e-15);
  EXPECT_DOUBLE_EQ(wrapAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrapAngle(-kPi), kPi);  // (-pi, pi]
  EXPECT_NEAR(wrapAngle(3 * kPi), kPi, 1e-12);
  const Vec3 w = wrapAngles(Vec3(4.0, -4.0, 0.1));
  EXPECT_NEAR(w.x(), 4.0 - 2 * kPi, 1e-15);
  EXPECT_NEAR(w.y(), -4.0 + 2 * kPi, 1e-15);
}

TEST(RotationVector, RoundTripsAndEdgeAngles) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> angle(0, kPi);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 axis = Vec3(n(rng), n(rng), n(rng)).normalized();
    const Vec3 v = angle(rng) * axis;
    EXPECT_LT((rotationVector(fromRotationVector(v)) - v).norm(), 1e-12) << v.transpose();
  }
  // Tiny angles keep their relative accuracy; zero is zero.
  const Vec3 tiny(1e-12, -2e-12, 3e-13);
  EXPECT_LT((rotationVector(fromRotationVector(tiny)) - tiny).norm(), 1e-24);
  EXPECT_EQ(rotationVector(Mat3::Identity()), Vec3::Zero());
  EXPECT_EQ(fromRotationVector(Vec3::Zero()), Mat3::Identity());
  // Near and at pi: the angle is pi, the axis is +/- the true one.
  for (double a : {kPi - 1e-9, kPi}) {
    const Vec3 axis = Vec3(1, 2, -2).normalized();
    const Vec3 r = rotationVector(fromRotationVector(a * axis));
    EXPECT_NEAR(r.norm(), a, 1e-9);
    EXPECT_NEAR(std::abs(r.normalized().dot(axis)), 1.0, 1e-12);
  }
  // A turn of 3/2 pi comes back as the short way round.
  const Vec3 r = rotationVector(rotZ(1.5 * kPi));
  EXPECT_LT((r - Vec3(0, 0, -0.5 * kPi)).norm(), 1e-12);
}

TEST(RotationVector, OrthonormalizedIsTheNearbyRotation) {
  const Mat3 R = paperRotation(Vec3(0.3, -0.4, 2.0));
  Mat3 noisy = R;
  noisy(0, 1) += 1e-7;
  const Mat3 fixed = orthonormalized(noisy);
  EXPECT_LT((fixed * fixed.transpose() - Mat3::Identity()).norm(), 1e-14);
  EXPECT_LT((fixed - R).norm(), 1e-6);
}

}  // namespace
}  // namespace hg::math
