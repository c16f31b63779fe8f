#pragma once
// `hapticgrasp bench scene`: what a scene's size costs. Every solid of a file (an assembly),
// repeated N times side by side, becomes a scene built as the workbench builds one
// (SceneBuild: coarse stand-ins at once, each distinct shape's model once, in the
// background, nearest the hand first); the REAL servo thread runs the two-finger method at
// the given rate with a scripted hand that comes down onto the largest part of the first
// copy and presses 1 mm into it.
//
//   start_s        the call until the servo runs (the file is read before: a document open)
//   first_touch_s  the call until the first contact force from that part's own model
//   all_built_s    the call until every distinct model is built
//   memory_bytes   resident memory grown from before the scene to the end
//   compute_us     the servo loop's own work per tick (device I/O excluded)
#include <string>

#include "hapticgrasp/servo/servo_loop.hpp"
#include "hapticgrasp/servo/timing_stats.hpp"

namespace hg::servo {

struct SceneBenchOptions {
  std::string part;        // a .step or .brep file (or a sample part's name)
  int copies = 1;          // the file's solids, this many times side by side along x
  double seconds = 5;      // servo time at least (longer until every model is built)
  double rate_hz = 2000;
  int workers = 1;         // model-building threads
  bool share = true;       // copies share their shapes' models (false: every copy built apart)
  bool pin = true;         // a real-time servo keeps a CPU to itself, the builders the others
  bool realtime = true;
  // How each model is loaded: "shape" (the solid as read, in this process), "text" (its BREP
  // text, in this process: the workbench without its loader), "loader" (its BREP text in the
  // loader process: the workbench's way, geometry/loader_process.hpp).
  std::string load = "shape";
  AllocationCounter allocationCounter = nullptr;
};

struct SceneBenchResult {
  std::size_t parts = 0, uniqueModels = 0, failedModels = 0;
  double read_s = 0, start_s = 0, first_touch_s = -1, all_built_s = -1;
  long memory_bytes = 0;
  DurationSummary compute, periodError;
  double achieved_hz = 0;
  long allocations_in_loop = -1;
  std::string scheduler;
  std::string target;        // the part touched
  std::string load;          // as asked (SceneBenchOptions::load)
  std::size_t loaderProcesses = 0;  // "loader": helper processes started
};

// Throws GeometryError for an unreadable file, std::invalid_argument for bad options.
SceneBenchResult runSceneBench(const SceneBenchOptions& options);
// {"parts", "unique_models", "failed_models", "read_s", "start_s", "first_touch_s",
//  "all_built_s", "memory_bytes", "compute_us": {"p50","p99","max"}, "period_err_us": {...},
//  "achieved_hz", "allocations_in_loop", "scheduler", "target", "load", "loader_processes"}
std::string toJson(const SceneBenchResult& result, int indent = 2);

}  // namespace hg::servo
