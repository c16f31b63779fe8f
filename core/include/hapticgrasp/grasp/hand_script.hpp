#pragma once
// A scripted hand: fingertips and wrist moved through keyframes, for experiments, demos
// and tests that need the same hand motion at any servo rate. Positions are linear between
// keys; a turn of the whole hand about a vertical axis is interpolated as an angle, so a
// turning hand sweeps arcs, not chords.
#include <array>
#include <vector>

#include "hapticgrasp/grasp/hand_sample.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"

namespace hg::grasp {

struct HandKey {
  double t = 0;                 // s, increasing from key to key
  Vec3 index = Vec3::Zero();    // fingertips and wrist in the script's frame
  Vec3 thumb = Vec3::Zero();
  Vec3 wrist = Vec3::Zero();
  Vec3 shift = Vec3::Zero();    // then the whole hand moved by this (absolute frame)
  double turn = 0;              // ... after turning it by this (rad) about `up` through `pivot`
  std::array<Vec3, HandSample::kMaxFingertips - 2> extra{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  // fingertips 2..4

  Vec3& fingertip(int k) { return k == 0 ? index : k == 1 ? thumb : extra[static_cast<std::size_t>(k - 2)]; }
};

class HandScript {
 public:
  // `frame` places the script's frame in the absolute one; `wristRotation` is the wrist's
  // orientation in the script's frame. Throws std::invalid_argument for no keys or keys
  // out of time order.
  HandScript(std::vector<HandKey> keys, const PartPose& frame = {}, const Vec3& pivot = Vec3::Zero(),
             const Vec3& up = Vec3::UnitZ(), const Mat3& wristRotation = Mat3::Identity());

  HandSample at(double t) const noexcept;  // held before the first and after the last key
  double duration() const { return keys_.back().t; }

 private:
  std::vector<HandKey> keys_;
  PartPose frame_;
  Vec3 pivot_, up_;
  Mat3 wristRotation_;
};

}  // namespace hg::grasp
