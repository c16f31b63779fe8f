#pragma once
// Vector and matrix types of the core. Everything is SI (m, kg, s, N) unless a name says otherwise.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace hg {
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
}  // namespace hg
