#pragma once
// The servo loop: a dedicated thread at 1-8 kHz. Each tick is a short list of named stages
// over a small per-tick state (DESIGN.md: the tick reads like MuJoCo's mj_step):
//   drain commands, read device, watchdog, grasp step, passivity, saturate, output gain,
//   write device, publish snapshot, push record.
// step() runs one tick on the caller's thread with given times (replay, tests).
//
//   GUI thread --send(ServoCommand)--> SPSC ring --> servo thread
//   servo thread --SeqLock<ServoSnapshot>--> any number of readers (GUI, recorder, tests)
//
// The tick never allocates, locks, throws or does I/O (the device's read/write are the
// device's business; the Device contract asks the same of them).
//
// Timing: clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME) on absolute deadlines k*T; the
// grasp gets the MEASURED dt; a tick that ends after its successor's deadline makes the
// loop skip to the next deadline after now (no catching up), and each skipped tick counts
// as an overrun. The thread asks for SCHED_FIFO and mlockall (current pages, and future ones
// as they are first touched: MCL_FUTURE | MCL_ONFAULT) and
// records what it got (see scheduler()); without privilege it runs SCHED_OTHER and says so.
//
// Watchdog: no new sample for longer than spec().timeout_s, or a sample with NaN/Inf,
// trips it: the grasp is reset at once (FREE, every part at its initial pose), the last
// command is held and scaled by a gain ramping linearly from its current value to 0 in
// ServoConfig::watchdogRamp_s (10 ms), then the device gets zero forces. The fault code and
// time are in the snapshot (and a kWatchdogTrip event); a fresh finite sample clears it
// (kWatchdogClear) and the gain ramps back up over the same time.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "hapticgrasp/contact/contact_report.hpp"
#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/grasp/grasp_parameters.hpp"
#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/hand_sample.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/scene/scene.hpp"
#include "hapticgrasp/servo/grasp_engine.hpp"
#include "hapticgrasp/servo/passivity.hpp"
#include "hapticgrasp/servo/seqlock.hpp"
#include "hapticgrasp/servo/spsc_ring.hpp"
#include "hapticgrasp/servo/tick_record.hpp"
#include "hapticgrasp/servo/timing_stats.hpp"

namespace hg::servo {

// Returns the number of heap allocations the CALLING thread has made so far (a malloc
// interposer's thread_local counter, e.g. tests/unit/alloc_counter.hpp or
// malloc_counter.hpp). Optional: tests and benchmarks only.
using AllocationCounter = long (*)();

struct ServoConfig {
  double rate_hz = 2000;             // 50 .. 10000 (the design range is 1-8 kHz)
  bool realtime = true;              // ask for SCHED_FIFO and mlockall
  int fifoPriority = 80;             // 1 .. 99
  // The CPU the thread is pinned to (-1: none, the scheduler's choice). Background work
  // (a scene's model build) keeps off it: SceneBuild::Options::avoidCpu.
  int cpu = -1;
  bool passivityController = false; // initial state; ServoCommand toggles it
  double watchdogRamp_s = 0.010;     // forces fall to zero within this after a fault
  AllocationCounter allocationCounter = nullptr;
  void validate() const;             // throws std::invalid_argument
};

// The CPU a real-time servo thread takes for itself: the last this process may run on, or
// -1 when it may run on one only (nothing to keep the background off).
int servoCpu() noexcept;

// Servo-level bits in the event stream, beside the grasp's GraspEvent bits (0-7).
enum ServoEvent : std::uint32_t {
  kWatchdogTrip = 1u << 16,   // fault raised: forces ramp to zero, grasp reset
  kWatchdogClear = 1u << 17,  // good samples resumed
  kGraspReset = 1u << 18,     // a ResetGrasp command was applied
};

// The names of the event bits raised, comma-separated ("index contact, grasp", "watchdog
// trip"); "" for none.
std::string eventsText(std::uint32_t events);

// Small POD commands from the GUI thread.
struct ServoCommand {
  enum class Kind : std::uint8_t { ResetGrasp, SetPassivityController, Stop };
  Kind kind = Kind::ResetGrasp;
  bool on = false;  // SetPassivityController
};

enum class WatchdogFault : std::uint8_t { None, Silent, NonFinite };
const char* toString(WatchdogFault fault);  // "none", "silent", "non-finite sample"

struct WatchdogStatus {
  WatchdogFault fault = WatchdogFault::None;  // active fault, None when healthy
  double faultTime_s = 0;       // loop time the active (or last) fault was raised
  double clearTime_s = -1;      // loop time the last fault cleared (-1: not yet)
  WatchdogFault lastFault = WatchdogFault::None;  // most recent fault, even if cleared
  std::uint64_t trips = 0;      // faults raised since start
  double gain = 1;              // output gain: 1 healthy, ramping to 0 on a fault
  double silence_s = 0;         // time since the last fresh sample
};

// One record of the event log: the tick that raised some events and the state change.
struct EventRecord {
  std::uint64_t tick = 0;
  double time_s = 0;
  std::uint32_t events = 0;
  grasp::GraspState from = grasp::GraspState::Free, to = grasp::GraspState::Free;
};

// Passivity ports: index fingertip, thumb fingertip, wrist, then fingertips 2..4 of hands
// that have them (HandSample::fingertip(k) is port kExtraPort + k - 2).
enum Port : int { kIndexPort = 0, kThumbPort = 1, kWristPort = 2, kExtraPort = 3, kPortCount = 6 };

// A part and where it stands (servo snapshots carry the few that move, not every part).
struct PartPlacement {
  int part = -1;  // in a put-down log, -1: every part back at its initial pose (a reset)
  grasp::PartPose pose;
};

struct ServoSnapshot {
  static constexpr int kEventLog = 64;
  static constexpr int kMaxMoving = 16;  // parts held or carried at once
  static constexpr int kMoveLog = 64;

  std::uint64_t tick = 0;        // 1 for the first tick
  const char* method = "";       // GraspEngine::name()
  int fingertips = 2;            // hand.fingertip(0 .. fingertips-1) are in use
  double time_s = 0;             // loop time (CLOCK_MONOTONIC since start) of this tick
  double dt_s = 0;               // measured since the previous tick
  grasp::GraspState state = grasp::GraspState::Free;
  std::uint32_t events = 0;      // bits raised THIS tick (GraspEvent | ServoEvent)
  bool freshSample = false;      // device.read returned a new sample this tick
  bool passivityController = false;
  grasp::HandSample hand;        // the last good sample
  device::DeviceCommand raw;     // what the grasp asked for
  device::DeviceCommand sent;    // after passivity controller, saturation and watchdog gain
  bool saturated = false;        // some vector of `sent` was clamped this tick
  int graspedPart = -1;
  contact::ContactReport contact;  // part-to-part contact of the last grasp step (part -1: none)
  WatchdogStatus watchdog;
  double energy_J[kPortCount] = {};   // passivity observer E(n) per Port (see passivity.hpp)
  double alpha_Ns_per_m[kPortCount] = {};  // passivity controller damping this tick
  long allocations = -1;         // servo-thread allocations since the first tick; -1: no counter
  TimingSummary timing;          // refreshed every 64 ticks (and on the last tick)
  std::uint64_t tickMid = 0;     // == tick (consistency check for readers)
  // Event log: the last kEventLog ticks that raised events; record i of the total
  // `eventCount` is at eventLog[i % kEventLog].
  std::uint64_t eventCount = 0;
  EventRecord eventLog[kEventLog] = {};
  std::uint64_t eventTotals[32] = {};  // per event bit, raised since start
  // Where the parts are, whatever the scene's size (PoseTracker rebuilds every part's pose
  // from these): the parts moving this tick, and a log of the parts that stopped moving
  // (put down, or a reset), record i of `moveCount` at moveLog[i % kMoveLog].
  int partCount = 0;             // the scene's size
  int movingCount = 0;
  PartPlacement moving[kMaxMoving];
  std::uint64_t moveCount = 0;
  PartPlacement moveLog[kMoveLog];
  std::uint64_t tickEnd = 0;     // == tick (consistency check for readers)
};

// Per-reader cursor: the events raised since this reader's previous read.
class SnapshotReader {
 public:
  // OR of the event bits of the log records newer than the previous call's snapshot.
  // `lost` is set when more than kEventLog event ticks went by unseen (the OR is then of
  // what the log still holds, plus eventTotals changes).
  std::uint32_t eventsSinceLastRead(const ServoSnapshot& snapshot, bool* lost = nullptr) noexcept;

 private:
  std::uint64_t seen_ = 0;  // eventCount at the previous read
  std::uint64_t totals_[32] = {};
};

class ServoLoop {
 public:
  // A grasp method never steps further than this at once. A tick that comes late (the OS or
  // the machine's host held the thread) is crossed in that many steps, the hand moving
  // straight from its last sample to the new one, capped at kMaxGraspSubsteps steps (a
  // longer gap takes longer ones): a held part then follows as if the loop had kept time.
  // As one step, a 250 ms gap let the 2 kg cylinder slip 44 mm in a multi-finger pinch
  // (tests/unit/test_servo_loop.cpp: ALateTickIsCrossedInShortSteps) and 400 ms dropped it.
  static constexpr double kMaxGraspStep_s = 0.005;
  static constexpr int kMaxGraspSubsteps = 64;

  // The first paper's two-finger method over `scene`. Throws std::invalid_argument for a
  // null device or scene, or a bad config.
  ServoLoop(std::shared_ptr<device::Device> device, grasp::ScenePtr scene,
            const grasp::GraspParameters& parameters = {}, const ServoConfig& config = {});
  // Any method, any number of parts; also throws when the device reads fewer fingertips
  // than the method needs.
  ServoLoop(std::shared_ptr<device::Device> device, std::unique_ptr<GraspEngine> engine,
            const ServoConfig& config = {});
  ~ServoLoop();  // stop()s
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  // Starts the thread; returns once it has set its scheduling (see scheduler()). Throws
  // std::logic_error if already running or the loop was used before. With realtime, the
  // mlockall is process-wide and undone (munlockall) when this loop's thread exits.
  void start();
  // Asks the thread to stop, joins it (it checks the flag every tick and after every
  // sleep, so this returns within about one period plus one tick), leaves the device idle.
  void stop() noexcept;
  bool running() const noexcept { return running_.load(std::memory_order_acquire); }

  // GUI thread (a single producer). False if the ring is full.
  bool send(const ServoCommand& command) noexcept { return commands_.push(command); }

  // Records every tick into `ring` (a recorder's writer thread drains it). Before start().
  void record(std::shared_ptr<TickRecordRing> ring);

  // One tick on the CALLING thread at loop time t, dt since the previous tick: the same
  // stages the thread runs, for replay (re-simulation from a recording) and for tests.
  // Throws std::logic_error once start() was called.
  void step(double t, double dt);

  // Any thread. False before the first tick.
  bool read(ServoSnapshot& out) const noexcept { return snapshot_.read(out); }
  const SeqLock<ServoSnapshot>& snapshots() const noexcept { return snapshot_; }

  // Valid after start(): "SCHED_FIFO" or "SCHED_OTHER (EPERM: Operation not permitted)";
  // memoryLock(): "mlockall" or "none (EPERM: ...)".
  const std::string& scheduler() const noexcept { return scheduler_; }
  const std::string& memoryLock() const noexcept { return memoryLock_; }
  // Valid after start(): "cpu 1", or "any (not requested)", or why the pin failed.
  const std::string& affinity() const noexcept { return affinity_; }
  // Timing so far (exact as of the last snapshot refresh; final after stop()).
  TimingSummary timing() const noexcept;
  const ServoConfig& config() const noexcept { return config_; }

 private:
  // What one tick's stages hand each other; lives on the servo thread's stack.
  struct TickState {
    double t = 0, dt = 0;
    std::int64_t computeStart_ns = 0, io_ns = 0;
    std::uint32_t events = 0;
    std::uint8_t commands = 0;     // TickCommand bits applied
    grasp::GraspState before = grasp::GraspState::Free;
    bool fresh = false, good = false;
    std::uint64_t publications = 0;  // the scene's model swaps published when the tick began
    device::DeviceCommand out;     // what the device is given
  };

  void run() noexcept;
  void tick(double now, double dt) noexcept;
  // The stages, in order.
  void drainCommands(TickState& s) noexcept;
  void readDevice(TickState& s) noexcept;
  void watchdog(TickState& s) noexcept;
  void graspStep(TickState& s) noexcept;
  void passivity(device::DeviceCommand& command) noexcept;
  void saturate(device::DeviceCommand& command) noexcept;
  void outputGain(TickState& s) noexcept;
  void writeDevice(TickState& s) noexcept;
  void publishSnapshot(TickState& s) noexcept;
  void pushRecord(const TickState& s) noexcept;

  void publish() noexcept;
  void logMove(int part, const grasp::PartPose& pose) noexcept;
  void publishPoses() noexcept;

  std::shared_ptr<device::Device> device_;
  std::unique_ptr<GraspEngine> engine_;
  ServoConfig config_;
  SpscRing<ServoCommand, 64> commands_;
  SeqLock<ServoSnapshot> snapshot_;

  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> running_{false};
  std::atomic<bool> started_{false};
  std::atomic<bool> ready_{false};
  std::string scheduler_ = "not started", memoryLock_ = "not started", affinity_ = "not started";
  bool locked_ = false;

  // Servo-thread data (touched by the thread only while it runs).
  ServoSnapshot snap_;               // the snapshot being built
  device::DeviceSample sample_;
  grasp::HandSample lastHand_;
  bool haveHand_ = false;
  double lastFresh_s_ = 0;           // loop time of the last fresh finite sample
  double pendingDt_ = 0;             // time since the last grasp step
  double sampleDt_ = 0;              // time since the last fresh sample
  device::DeviceCommand held_;       // last command before the fault, ramped down
  device::DeviceCommand lastOut_;    // last command computed (after controller and saturation)
  double gain_ = 1;
  double faultStart_s_ = 0;
  PassivityPort ports_[kPortCount];
  TimingSummary timingSummary() const noexcept;
  DurationHistogram periodError_, compute_, deviceIo_;
  std::uint64_t ticks_ = 0, overruns_ = 0, lateTicks_ = 0;
  double firstTick_s_ = 0, lastTick_s_ = 0;
  double lastPeriodError_s_ = 0;     // |dt - period| of the current tick
  long allocationBase_ = 0;
  bool passivityOn_ = false;
  TimingSummary final_;              // written by the thread before it exits
  int wasMoving_[ServoSnapshot::kMaxMoving] = {};  // the parts moving at the previous tick
  int wasMovingCount_ = 0;
  std::shared_ptr<TickRecordRing> records_;  // null: not recording
  TickRecord record_;                        // the record being built (servo thread)
};

}  // namespace hg::servo
