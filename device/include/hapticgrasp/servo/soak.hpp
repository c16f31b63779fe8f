#pragma once
// `hapticgrasp soak --minutes M`: the REAL servo thread at 2 kHz for M minutes, over the
// sample parts in turn (cylinder, block, loft: the perforated plate has a hole where the
// bench's hand grips), with both grasp methods in turn
// (two-finger; multi-finger with three fingertips), in segments of up to a minute: each is
// the servo benchmark (servo_bench.hpp) with its scripted hand grasping, lifting and putting
// the part down, that hand wandering (FaultInjectingDevice), and the faults a real session
// meets injected at random: silence, NaN and Inf samples, stalls of 5-50 ms inside read(),
// the device unplugged and back, and the part's model swapped mid-session (a new back end
// published as the workbench's background build does); every segment is recorded (MCAP).
// What it judges: every fault handled (fault_injecting_device.hpp), no NaN out, no
// allocation on the servo thread, memory flat once every part and method has been met.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hapticgrasp/device/fault_injecting_device.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"

namespace hg::servo {

struct SoakOptions {
  double minutes = 1;
  double rate_hz = 2000;
  bool realtime = true;
  std::uint64_t seed = 1;
  double faultsPerMinute = 30;  // device faults; plus a model swap in every segment
  bool record = true;           // record each segment (deleted once summed up)
  std::string recordDir;        // empty: a private folder under $TMPDIR
  AllocationCounter allocationCounter = nullptr;
};

struct SoakResult {
  double seconds = 0;
  int segments = 0;
  std::uint64_t ticks = 0;
  std::uint64_t nan_outputs = 0;
  std::uint64_t unbounded_outputs = 0;
  long allocations = -1;  // on the servo threads, summed; -1: not measured
  std::array<std::uint64_t, device::kFaultKinds> injected{}, handled{};
  std::uint64_t faults_injected = 0, faults_handled = 0;
  // The first kMaxUnhandledListed faults not handled, each a line: its segment (part,
  // method, contact), kind, time in the segment, duration and why (fault_injecting_device.hpp).
  static constexpr std::size_t kMaxUnhandledListed = 20;
  std::vector<std::string> unhandled;
  std::int64_t rss_growth_bytes = 0;  // resident memory at the end less after the first cycle (every part, method and contact)
  std::int64_t rss_bytes = 0;         // at the end
  std::int64_t heap_growth_bytes = 0; // malloc's bytes in use, the same way: a leak or a cache, not fragmentation
  double max_period_err_us = 0;       // as the loop measured it, the injected stalls included
  double max_period_err_unstalled_us = 0;  // the tick after each stall left out
  // The loop's own work in its longest tick: against the period error above, it tells a
  // late wake-up (the machine) from a long tick (the loop's own computation).
  double max_compute_us = 0;
  double achieved_hz_min = 0;
  std::uint64_t grasps = 0, lifts = 0, watchdog_trips = 0, watchdog_clears = 0;
  // Part-to-part contact (a floor under the part) in every other pair of segments, so that
  // in two rounds each part meets it with both methods: the segments, the 10 ms looks that
  // found the part pressed on the floor, and the deepest interference then.
  int contact_segments = 0;
  std::uint64_t contact_polls = 0;
  double contact_max_penetration_m = 0;
  std::uint64_t recorded_bytes = 0, dropped_records = 0;
  std::string recording_error;  // the first, if any
  std::string scheduler;
  bool passed() const;          // zero NaN, zero allocations, every fault handled, growth < 2 MB
};

// Throws std::invalid_argument for minutes outside (0, 1440] or a bad rate.
SoakResult runSoak(const SoakOptions& options);

// {"seconds", "segments", "ticks", "nan_outputs", "unbounded_outputs", "allocations",
//  "faults_injected", "faults_handled", "faults": {kind: {"injected", "handled"}}, "unhandled": [line],
//  "rss_growth_bytes", "rss_bytes", "heap_growth_bytes", "max_period_err_us", "max_period_err_unstalled_us",
//  "max_compute_us",
//  "achieved_hz_min", "grasps", "lifts", "watchdog_trips", "watchdog_clears",
//  "recording": {"bytes", "dropped_records", "error"}, "scheduler", "passed"}
std::string toJson(const SoakResult& result, int indent = 2);

}  // namespace hg::servo
