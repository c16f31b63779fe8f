#include "hapticgrasp/grasp/grasp_frame.hpp"

#include "hapticgrasp/math/rpy.hpp"

namespace hg::grasp {
namespace {

// `v` without its component along unit `axis`, normalised; false if nothing is left.
bool orthogonalUnit(const Vec3& v, const Vec3& axis, Vec3& out) {
  const Vec3 rest = v - axis.dot(v) * axis;
  const double n = rest.norm();
  if (!(n > 1e-6)) return false;
  out = rest / n;
  return true;
}

}  // namespace

Mat3 handFrame(const Vec3& index, const Vec3& thumb, const Vec3& wrist, const Mat3& lastGood,
               const GraspParameters& k) noexcept {
  const Vec3 span = index - thumb;
  const double distance = span.norm();
  if (!(distance > k.minFingerDistance_m)) return lastGood;  // eq 16 undefined
  const Vec3 h1 = span / distance;                             // eq 16
  const Vec3 lever = index - wrist;
  const Vec3 normal = h1.cross(lever);
  const double n = normal.norm();
  Vec3 h2;
  if (n > k.minWristSine * lever.norm() && n > 0) {
    h2 = normal / n;  // eq 17
  } else if (!orthogonalUnit(lastGood.col(1), h1, h2) && !orthogonalUnit(lastGood.col(2), h1, h2)) {
    return lastGood;  // wrist on the finger line and h1 along both old axes: cannot happen for a unit frame
  }
  Mat3 frame;
  frame.col(0) = h1;
  frame.col(1) = h2;
  frame.col(2) = h1.cross(h2);  // eq 18
  return frame;
}

Mat3 firstHandFrame(const HandSample& hand, const GraspParameters& k) noexcept {
  return handFrame(hand.index, hand.thumb, hand.wrist, math::orthonormalized(hand.wristRotation), k);
}

GraspMemory preserveGrasp(const HandSample& hand, const PartPose& object, const Mat3& frame) noexcept {
  GraspMemory m;
  m.object = object;
  m.xi_o = math::paperRpy(object.rotation.transpose());
  m.h_o = object.rotation.transpose() * frame;                 // eqs 12-14: h_bar^o = R h^a
  m.x_m_o = object.toObject(0.5 * (hand.index + hand.thumb));  // eq 15
  m.distance = (hand.index - hand.thumb).norm();
  return m;
}

PartPose graspedPose(const GraspMemory& memory, const Mat3& frame, const Vec3& index, const Vec3& thumb) noexcept {
  PartPose pose;
  // Eq 20, R = [h_bar^o] [h^a]^-1, with [h^a]^-1 = [h^a]^T; the pose keeps its transpose.
  pose.rotation = frame * memory.h_o.transpose();
  pose.position = 0.5 * (index + thumb) - pose.rotation * memory.x_m_o;  // eq 22
  return pose;
}

}  // namespace hg::grasp
