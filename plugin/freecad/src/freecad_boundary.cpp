#include "freecad_boundary.hpp"

#include <cmath>
#include <stdexcept>

namespace hg::freecad {

double toMetres(double mm) { return mm * kMetresPerMm; }
double toMillimetres(double m) { return m / kMetresPerMm; }

Vec3 toMetres(const std::array<double, 3>& mm) { return {toMetres(mm[0]), toMetres(mm[1]), toMetres(mm[2])}; }

std::array<double, 3> toMillimetres(const Vec3& m) { return {toMillimetres(m.x()), toMillimetres(m.y()), toMillimetres(m.z())}; }

grasp::PartPose toPose(const Placement& placement) {
  const auto& q = placement.quaternion;
  Quat quat(q[3], q[0], q[1], q[2]);  // Eigen: (w, x, y, z)
  const Vec3 base = toMetres(placement.base_mm);
  if (!base.allFinite()) throw std::invalid_argument("placement base is not finite");
  if (!quat.coeffs().allFinite() || quat.norm() < 1e-9)
    throw std::invalid_argument("placement rotation is not a rotation (quaternion not finite or zero)");
  quat.normalize();
  grasp::PartPose pose;
  pose.rotation = quat.toRotationMatrix();
  pose.position = base;
  return pose;
}

Placement toPlacement(const grasp::PartPose& pose) {
  Quat quat(pose.rotation);
  quat.normalize();
  if (quat.w() < 0) quat.coeffs() = -quat.coeffs();
  Placement placement;
  placement.base_mm = toMillimetres(pose.position);
  placement.quaternion = {quat.x(), quat.y(), quat.z(), quat.w()};
  return placement;
}

grasp::HandKey toHandKey(const HandKeyMm& key) {
  grasp::HandKey k;
  k.t = key.t;
  k.index = toMetres(key.index_mm);
  k.thumb = toMetres(key.thumb_mm);
  k.wrist = toMetres(key.wrist_mm);
  k.shift = toMetres(key.shift_mm);
  k.turn = key.turn;
  return k;
}

}  // namespace hg::freecad
