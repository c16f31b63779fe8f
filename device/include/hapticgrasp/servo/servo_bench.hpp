#pragma once
// `hapticgrasp bench servo`: the REAL servo thread at a given rate for a given time, with a
// hand grasping, lifting and putting down a part over and over:
//  - device "arm": the simulated master arm (SimulatedMasterArm, KDL dynamics) moved by a
//    SimulatedOperator; the arm is advanced on the servo thread inside each read() by the
//    adapter's own clock (servo/advancing_device.hpp), so compute_us includes the arm's
//    simulation step as well as the grasp and the torque mapping. The part is placed below
//    the arm's resting hand, turned about z so that its y axis lies along the hand's grip
//    axis; the fingertips open, come down outside the part's +-y sides at mid-height (at
//    most 25 mm below the top) and the x centre of its bounds, close (grasp), lift 5 cm,
//    hold, put it down and open (a 1.7 s cycle after 0.25 s of reaching; the first grasp
//    comes at about 1 s, the first lift at about 1.2 s). The hand opens to about 10 cm, so a
//    part wider than that across y (the paper's 0.1 m cylinder) is not straddled: the
//    fingertips come down onto its top.
//  - device "scripted": a ScriptedHandDevice replaying a grasp::HandScript; for the
//    cylinder, the paper's cylinder (0.1 m x 0.4 m, 2 kg) lying along y (benchScene(),
//    benchScript()); other parts are grasped across their y sides like the arm does.
//
// method "multi-finger" runs the resultant-force paper's method (MultiFingerEngine) instead
// of the two-finger state machine, with `fingers` fingertips: the arm has two; the scripted
// hand puts the thumb (fingertip 1) on the part's -y side and the others side by side
// along x on its +y side, 15 mm apart, and closes them far enough in for friction to carry
// the part's weight (1.5 m g / (2 μ k) each); the paper cylinder is then grasped across y
// like any other part.
//
// allocations_in_loop: the heap allocations made BY THE SERVO THREAD from its first tick
// to its last, counted by an AllocationCounter -- a malloc/calloc/realloc interposer with
// a thread_local count, linked into the executable only (include
// hapticgrasp/servo/malloc_counter.hpp in exactly one translation unit of it and pass
// hg::servo::threadAllocations). Without one it is -1 ("not measured").
#include <functional>
#include <memory>
#include <string>

#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"

namespace hg::servo {

struct ServoBenchOptions {
  double rate_hz = 2000;
  double seconds = 2;
  bool realtime = true;
  std::string part = "cylinder";  // a sample part (cylinder, block, loft, plate) or a .brep/.step file (mm)
  std::string device = "arm";     // "arm" | "scripted"
  std::string backend = "auto";   // penetration back end: auto (analytic for primitives, exact otherwise), exact, analytic, mesh
  std::string method = "two-finger";  // "two-finger" | "multi-finger"
  int fingers = 2;                // fingertips of the multi-finger method (1-5; the arm has 2)
  AllocationCounter allocationCounter = nullptr;
  std::string recordPath;         // non-empty: record the session there (MCAP, session/recorder.hpp)
  // A floor plate the part stands on, and part-to-part contact as the workbench has it
  // (contact/carried_contact.hpp): the scripted put-down sets the part back onto the floor.
  bool contact = false;
  // For the soak (servo/soak.hpp): the device the loop gets, made from the bench's own (unset:
  // the bench's), and a call every 10 ms from the bench's own thread with the scene and the
  // seconds since the loop started (the soak swaps a model there).
  std::function<std::shared_ptr<device::Device>(std::shared_ptr<device::Device>)> wrapDevice;
  std::function<void(const grasp::Scene&, double)> poll;
};

// What recording cost and wrote (`bench servo --record`, `record`).
struct RecordingResult {
  bool enabled = false;
  std::string path;
  std::uint64_t droppedRecords = 0;  // ticks lost because the writer fell behind
  std::uint64_t bytes = 0;
  std::uint64_t messages = 0;
  std::uint64_t ticks = 0;           // tick records written
  std::string error;                 // why recording stopped early ("" if it did not)
};

struct ServoBenchResult {
  std::string part;              // the part's name
  std::string device;            // "arm" | "scripted"
  std::string backend;           // the penetration back end used ("exact", "analytic", ...)
  std::string method;            // "two-finger" | "multi-finger"
  int fingers = 2;
  double target_hz = 0;
  double achieved_hz = 0;
  double seconds = 0;
  std::string scheduler;        // "SCHED_FIFO" or "SCHED_OTHER (EPERM: ...)"
  std::string memory_lock;      // "mlockall" or "none (...)"
  DurationSummary period_err;   // |dt - T|, us
  DurationSummary compute;      // the loop's own work per tick, us (device I/O excluded)
  DurationSummary deviceIo;     // the device's read() + write(), us
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;
  long allocations_in_loop = -1;
  std::uint64_t grasps = 0;     // kGrasp events seen (the script did grasp)
  std::uint64_t lifts = 0;      // kLift events
  std::uint64_t watchdog_trips = 0;
  std::uint64_t watchdog_clears = 0;  // kWatchdogClear events: good samples resumed
  // With `contact`: the bench's 10 ms looks at the snapshot that found the part coupled to the
  // floor, and the deepest interference any of them reported.
  std::uint64_t contact_polls = 0;
  double contact_max_penetration_m = 0;
  RecordingResult recording;
};

// Throws std::invalid_argument for a rate outside [50, 10000] Hz, seconds not in (0, 3600],
// an unknown device or method, or more fingers than the device has; GeometryError for an unknown part or back end.
ServoBenchResult runServoBench(const ServoBenchOptions& options);
// The "arm" bench without the real-time thread, for tests: the same part placement, arm,
// simulated operator and 1.7 s cycle (and its ResetGrasp), the arm advanced in sub-steps of
// at most maxStep_s and the two-finger grasp stepped at rate_hz in lock-step, so the run is
// deterministic. Counts the grasp events; maxCarriedOpening_m is the largest fingertip
// distance beyond the distance at the grasp while the part is carried (MANIPULATE, until
// the hand starts to open at 1.55 s into the cycle): it releases at d_h.
struct OfflineArmBenchResult {
  int grasps = 0, lifts = 0, releases = 0;
  double maxCarriedOpening_m = 0;
};
OfflineArmBenchResult simulateArmBench(const std::string& part, double seconds, double rate_hz = 2000,
                                       double maxStep_s = 0.5e-3);

// The original benchmark: device "scripted", the paper's cylinder.
ServoBenchResult runServoBench(double rate_hz, double seconds, bool realtime = true,
                               AllocationCounter allocationCounter = nullptr);

// {"part", "device", "backend", "target_hz", "achieved_hz", "seconds", "scheduler", "memory_lock",
//  "period_err_us": {"p50","p99","max"}, "compute_us": {"p50","p99","max"}, "ticks",
//  "overruns", "allocations_in_loop", "grasps", "lifts", "watchdog_trips", "method", "fingers"}
// and, when recording, "recording": {"path", "dropped_records", "bytes", "messages", "ticks", "error"}
std::string toJson(const ServoBenchResult& result, int indent = 2);

// The script and scene the benchmark uses (a 2 s cycle: approach, grasp, lift, put down,
// release), for tests and demos.
grasp::ScenePtr benchScene();
grasp::HandScript benchScript();

}  // namespace hg::servo
