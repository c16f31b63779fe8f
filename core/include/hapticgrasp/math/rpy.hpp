#pragma once
// The first paper's roll-pitch-yaw convention (Maekawa & Hollerbach, eqs 1 and 21), and
// rotation vectors. The core keeps orientations as rotation matrices; RPY exists only
// where the paper's equations are reproduced and at I/O.
//
// Beware the direction: the paper's R(xi) maps ABSOLUTE vectors into the OBJECT frame
// (x^o = R(xi)(x^a - x_o^a), eq 2). It is the transpose of a part's pose rotation
// (object -> absolute): R(xi) = (Rx(roll) Ry(pitch) Rz(yaw))^T.
#include "hapticgrasp/math/types.hpp"

namespace hg::math {

// Eq 1: R(xi) for xi = (roll, pitch, yaw) in radians; absolute -> object.
Mat3 paperRotation(const Vec3& rpy) noexcept;

// Eq 21, done robustly: the inverse of eq 1 for any rotation matrix, with pitch in
// [-pi/2, pi/2] from atan2(R31, hypot(R11, R21)) and roll taken after yaw has been
// removed, so nothing divides by cos(yaw) (as the printed eq 21 does) and the round trip
// R(paperRpy(R)) == R holds at pitch = +/-90 degrees too (there, yaw = 0 by choice).
Vec3 paperRpy(const Mat3& R) noexcept;

// Eq 21 exactly as printed, for comparison in tests only: NaN or wrong at yaw = +/-90 deg.
Vec3 paperRpyAsPrinted(const Mat3& R) noexcept;

// Angle wrapped into (-pi, pi]; each component of a vector.
double wrapAngle(double a) noexcept;
Vec3 wrapAngles(const Vec3& a) noexcept;

// The rotation vector (axis * angle, angle in [0, pi]) of a rotation matrix, and back.
// Through the quaternion, so it stays accurate near 0 and near pi.
Vec3 rotationVector(const Mat3& rotation) noexcept;
Mat3 fromRotationVector(const Vec3& v) noexcept;

// The nearest rotation to a 3x3 matrix that is roughly one (through the quaternion).
Mat3 orthonormalized(const Mat3& m) noexcept;

}  // namespace hg::math
