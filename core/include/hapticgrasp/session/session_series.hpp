#pragma once
// A recording reduced for reading: what a report plots and tabulates, from one streaming
// pass over the ticks (a 10-minute session at 2 kHz is 1.2 million of them).
//  - Series in time bins (at most maxBins, each the LARGEST value in its bin, so a force
//    peak never disappears in the reduction): fingertip forces, grasping force, wrist force
//    and moment, the largest force asked for before saturation, the moving part's travel,
//    compute time and period error.
//  - Every event and state change, exactly.
//  - The manipulations: each time a part was carried, from where to where, how far and how
//    much it turned, the largest force on the way.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/session/recording.hpp"

namespace hg::session {

struct SessionEvent {
  double time_s = 0;
  std::string text;  // "grasp, lift", "watchdog trip", ...
  grasp::GraspState from = grasp::GraspState::Free, to = grasp::GraspState::Free;
  std::uint32_t events = 0;
};

struct Manipulation {
  std::string part;
  double start_s = 0, end_s = 0;
  grasp::PartPose from, to;
  double distance_m = 0;   // |to - from| of the part's origin
  double angle_rad = 0;    // of the rotation from `from` to `to`
  double maxForce_N = 0;   // largest force sent while carried
};

struct SessionSeries {
  RecordingInfo info;
  double binWidth_s = 0;
  std::vector<double> time_s;                 // each bin's start, session time
  std::vector<std::array<double, 5>> fingertip_N;
  std::vector<double> grasp_N, wristForce_N, wristMoment_Nm, requested_N, travel_m, compute_us, periodError_us;
  std::vector<int> state;                     // GraspState at the bin's end
  std::vector<SessionEvent> events;
  std::vector<Manipulation> manipulations;
  std::uint64_t ticks = 0, saturatedTicks = 0, faults = 0;
  double maxForce_N = 0;                      // sent, any fingertip or the wrist
  double computeMax_us = 0, computeP99_us = 0;
};

// Throws McapError / SessionError as readRecordingInfo does; a truncated file reduces to
// what it holds.
SessionSeries readSessionSeries(const std::string& path, std::size_t maxBins = 2000);

// For the report (plugin/freecad/HapticGrasp/report.py): {"info": <recording info>,
// "bin_width_s", "time_s", "fingertip_N": [per fingertip: [...]], "grasp_N", "wrist_force_N",
// "wrist_moment_Nm", "requested_N", "travel_m", "compute_us", "period_error_us", "state",
// "state_names", "events": [{"time_s", "text", "from", "to", "fault"}], "manipulations":
// [{"part", "start_s", "end_s", "from_m", "to_m", "distance_m", "angle_deg", "max_force_N"}],
// "ticks", "saturated_ticks", "faults", "max_force_N", "compute_p99_us", "compute_max_us"}
std::string toJson(const SessionSeries& series);

}  // namespace hg::session
