#pragma once
// `hapticgrasp bench servo`: the REAL servo thread at a given rate for a given time, with a
// ScriptedHandDevice grasping, lifting, carrying and putting down the paper's cylinder
// (0.1 m x 0.4 m, 2 kg) over and over.
//
// allocations_in_loop: the heap allocations made BY THE SERVO THREAD from its first tick
// to its last, counted by an AllocationCounter -- a malloc/calloc/realloc interposer with
// a thread_local count, linked into the executable only (include
// hapticgrasp/servo/malloc_counter.hpp in exactly one translation unit of it and pass
// hg::servo::threadAllocations). Without one it is -1 ("not measured").
#include <string>

#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"

namespace hg::servo {

struct ServoBenchResult {
  double target_hz = 0;
  double achieved_hz = 0;
  double seconds = 0;
  std::string scheduler;        // "SCHED_FIFO" or "SCHED_OTHER (EPERM: ...)"
  std::string memory_lock;      // "mlockall" or "none (...)"
  DurationSummary period_err;   // |dt - T|, us
  DurationSummary compute;      // read -> write, us
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;
  long allocations_in_loop = -1;
  std::uint64_t grasps = 0;     // kGrasp events seen (the script did grasp)
  std::uint64_t lifts = 0;      // kLift events
  std::uint64_t watchdog_trips = 0;
};

// Throws std::invalid_argument for a rate outside [50, 10000] Hz or seconds not in (0, 3600].
ServoBenchResult runServoBench(double rate_hz, double seconds, bool realtime = true,
                               AllocationCounter allocationCounter = nullptr);

// {"target_hz", "achieved_hz", "seconds", "scheduler", "memory_lock",
//  "period_err_us": {"p50","p99","max"}, "compute_us": {"p50","p99","max"}, "ticks",
//  "overruns", "allocations_in_loop", "grasps", "lifts", "watchdog_trips"}
std::string toJson(const ServoBenchResult& result, int indent = 2);

// The script and scene the benchmark uses (a 2 s cycle: approach, grasp, lift, put down,
// release), for tests and demos.
grasp::ScenePtr benchScene();
grasp::HandScript benchScript();

}  // namespace hg::servo
