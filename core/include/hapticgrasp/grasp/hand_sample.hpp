#pragma once
// One reading of the operator's hand, absolute frame, SI: what the master arm's joint
// angles give through its kinematics (the first paper's x_i^a, x_t^a, x_w^a, xi_w^a).
// Hands with more fingertips (the resultant-force paper's method takes up to five) add
// them after the index and the thumb; fingertip(k) numbers them all: 0 index, 1 thumb,
// 2.. middle, ring, little. How many a device has is its DeviceSpec::fingertips.
#include <cmath>

#include "hapticgrasp/math/types.hpp"

namespace hg::grasp {

struct HandSample {
  static constexpr int kMaxFingertips = 5;
  double t = 0;                          // s; for the record (step() is given dt)
  Vec3 index = Vec3::Zero();             // x_i^a, tip of the index finger
  Vec3 thumb = Vec3::Zero();             // x_t^a, tip of the thumb
  Vec3 wrist = Vec3::Zero();             // x_w^a
  // Wrist -> absolute (the paper's xi_w^a). The grasp uses it only when the fingertips and
  // the wrist give no frame of their own at the moment of grasping (eqs 16-17 degenerate).
  Mat3 wristRotation = Mat3::Identity();
  Vec3 extra[kMaxFingertips - 2] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  // fingertips 2..4

  const Vec3& fingertip(int k) const { return k == 0 ? index : k == 1 ? thumb : extra[k - 2]; }
  Vec3& fingertip(int k) { return k == 0 ? index : k == 1 ? thumb : extra[k - 2]; }

  bool finite() const {
    for (const Vec3& e : extra)
      if (!e.allFinite()) return false;
    return std::isfinite(t) && index.allFinite() && thumb.allFinite() && wrist.allFinite() &&
           wristRotation.allFinite();
  }
};

// The hand a fraction f (0..1) of the way from `a` to `b`: fingertips, wrist and time
// straight, the wrist's orientation along the shortest turn (slerp). What the servo feeds a
// grasp method between two samples that came too far apart (servo_loop.cpp: graspStep).
HandSample between(const HandSample& a, const HandSample& b, double f) noexcept;

}  // namespace hg::grasp
