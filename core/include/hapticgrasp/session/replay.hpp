#pragma once
// Replay: re-simulates a recorded session from its hand samples and time steps through the
// same grasp engine, parameters and servo stages (ServoLoop::step: watchdog, passivity,
// saturation included), on the scene rebuilt from the recording's attached BREPs and
// recorded mass properties. On the build that recorded it the result is bit-identical;
// `check` says where it is not.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hapticgrasp/scene/scene.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"
#include "hapticgrasp/servo/tick_record.hpp"
#include "hapticgrasp/session/session_description.hpp"

namespace hg::session {

struct ReplayCheck {
  std::uint64_t ticks = 0;             // ticks re-simulated
  std::uint64_t stateMismatches = 0;   // ticks whose grasp state differs
  std::uint64_t eventMismatches = 0;   // ticks whose event bits differ
  double maxForceDiff_N = 0;           // largest difference of any force sent (N, or N m for the moment)
  double maxPoseDiff_m = 0;            // largest difference of a moving part's position
  std::uint64_t firstMismatchTick = 0; // 0: none
  bool complete = true;                // the recording was read to its end
  std::vector<std::string> warnings;   // a different build, a truncated file, ...
};

// The scene a recording describes: each part from its attached BREP (or its recorded box
// for a stand-in), with the recorded back end, mass properties and initial pose.
// Throws SessionError when an attachment is missing or does not load.
grasp::ScenePtr rebuildScene(const SessionDescription& description);

// The engine the description names over `scene`.
std::unique_ptr<servo::GraspEngine> rebuildEngine(const SessionDescription& description, grasp::ScenePtr scene);

// Re-simulates `path`. `onTick(recorded, replayed snapshot)` sees every tick (may be empty).
// Throws McapError/SessionError for a file that is not a recording.
ReplayCheck replay(const std::string& path,
                   const std::function<void(const servo::TickRecord&, const servo::ServoSnapshot&)>& onTick = {});

// {"ticks", "state_mismatches", "event_mismatches", "max_force_diff_N", "max_pose_diff_m",
//  "first_mismatch_tick", "complete", "warnings"}
std::string toJson(const ReplayCheck& check, int indent = 2);

}  // namespace hg::session
