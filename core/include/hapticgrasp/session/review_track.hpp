#pragma once
// A recording as the Review panel plays it back: one streaming pass over the ticks reduced
// to frames at a viewer's rate (plus one at every state change and event, so none is
// skipped over, and the last tick, so the track ends where the recording does), the moving
// parts' poses as keys (each part's pose at any time is its last
// key; exact at put-down, since a part's last pose is always kept), every event, and each
// part's last recorded model (the description's, or a model swap's) with its BREP, so that
// a recording opens with no document at all.
#include <cstddef>
#include <string>
#include <vector>

#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/hand_sample.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/session_series.hpp"

namespace hg::session {

struct ReviewFrame {
  static constexpr int kMaxFingertips = grasp::HandSample::kMaxFingertips;
  double time_s = 0;                 // session time (from the first message)
  grasp::GraspState state = grasp::GraspState::Free;
  bool fault = false;                // the watchdog holds a fault
  int graspedPart = -1;
  int fingertips = 2;
  Vec3 fingertip_m[kMaxFingertips] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  Vec3 wrist_m = Vec3::Zero();       // the last sample the device gave, world frame
  Vec3 force_N[kMaxFingertips] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  // as sent
  double grasp_N = 0;
};

struct PoseKey {
  double time_s = 0;
  grasp::PartPose pose;
};

// A reviewer's note with where the hand was then: the midpoint of the first two fingertips
// (index and thumb) at the first tick at or after the note's time, world frame. Not stored
// in the note itself: the ticks already hold every sample.
struct ReviewNote {
  Annotation note;
  Vec3 hand_m = Vec3::Zero();
};

struct ReviewTrack {
  RecordingInfo info;
  std::vector<ReviewFrame> frames;               // increasing time_s
  std::vector<std::vector<PoseKey>> poses;       // per part, increasing time_s; empty: it never moved
  std::vector<RecordedPart> models;              // per part: its last recorded model, BREP included
  std::vector<SessionEvent> events;
  std::vector<ReviewNote> notes;                 // info.annotations in time order, with the hand

  // The last frame at or before t (the first before it begins). Requires frames.
  std::size_t frameAt(double t) const;
  // Where part i stood at time t (its initial pose before its first key).
  grasp::PartPose poseAt(std::size_t part, double t) const;
  std::vector<int> movedParts() const;
};

// Throws McapError / SessionError as readRecordingInfo does, and SessionError for a
// recording without ticks; a truncated file gives what it holds.
ReviewTrack readReviewTrack(const std::string& path, double frameRate_hz = 60);

}  // namespace hg::session
