#pragma once
// A device that misbehaves on a schedule, for the soak (`hapticgrasp soak`, servo/soak.hpp)
// and the tests: it wraps a real back end and injects the faults a real device shows -
// silence, NaN and Inf samples, stalls inside read(), unplugging and plugging back - and
// judges from the commands the servo loop writes back whether the loop handled each one:
//   - every command finite, and within the device's spec (saturation held);
//   - silence, unplugging and non-finite samples: the forces are exactly zero once the
//     watchdog has had time to trip and ramp (spec().timeout_s for silence, then
//     rampAllowance_s), until the fault ends;
//   - after every fault (a stall and a model swap too), the loop goes on writing.
// The hand also wanders: a smooth offset (three sines an axis, random phases) moves the whole
// hand, so grasps are made and lost at ever-different places.
// read() and write() run on the servo thread: no allocation, no lock, no throw; the schedule
// and the verdicts are preallocated. markExternal() (another thread) registers an outside
// fault - a model swap - in a preallocated slot.
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "hapticgrasp/device/device.hpp"

namespace hg::device {

enum class FaultKind : std::uint8_t { Silence, NaNSample, InfSample, Stall, Unplug, ModelSwap };
inline constexpr int kFaultKinds = 6;
const char* toString(FaultKind kind);  // "silence", "nan", "inf", "stall", "unplug", "model swap"

struct Fault {
  FaultKind kind = FaultKind::Silence;
  double start_s = 0;     // device time (from the first read())
  double duration_s = 0;  // a stall sleeps this long once; a model swap has none
};

// A schedule of `seconds` with about `perMinute` faults of the device's kinds (not model
// swaps), at random times at least 0.5 s apart, with durations as a real device shows them:
// silence 0.1-0.5 s, NaN and Inf samples 20-100 ms, stalls 5-50 ms, unplugged 0.5-2 s. The
// kinds go round in turn from `firstKind` (silence, nan, inf, stall, unplug).
std::vector<Fault> randomFaults(double seconds, double perMinute, std::mt19937_64& random, int firstKind = 0);

struct WanderAmplitude {
  Vec3 amplitude_m = Vec3(0.015, 0.004, 0.010);  // per axis, the sum of three sines
  double minFrequency_Hz = 0.05, maxFrequency_Hz = 0.4;
};

// A fault the loop did not handle, and why, for a soak that fails to say what failed.
struct UnhandledFault {
  Fault fault;      // for a model swap: its time, duration zero
  std::string why;  // e.g. "forces not zero 31.0 ms into it"
};

struct FaultReport {
  std::array<std::uint64_t, kFaultKinds> injected{}, handled{};
  std::vector<UnhandledFault> unhandled;  // in the order they started, scheduled ones first
  std::uint64_t nanOutputs = 0;        // commands with a non-finite value
  std::uint64_t unboundedOutputs = 0;  // commands beyond the spec's force or torque
  std::uint64_t writesDropped = 0;     // while unplugged
  double maxPeriodErrUnstalled_us = 0;  // |read-to-read - T|, the read after a stall left out
  std::uint64_t totalInjected() const;
  std::uint64_t totalHandled() const;
};

class FaultInjectingDevice : public Device {
 public:
  static constexpr int kExternalSlots = 256;
  using Clock = std::function<double()>;  // seconds, monotonic; default steady_clock

  // `schedule` in device time, sorted by start, faults apart. rampAllowance_s: how long the
  // loop may take from detecting a fault to zero forces (its ramp plus two periods).
  FaultInjectingDevice(std::shared_ptr<Device> inner, std::vector<Fault> schedule, double rate_hz,
                       double rampAllowance_s, std::uint64_t wanderSeed = 0, WanderAmplitude wander = {},
                       Clock clock = {});

  const DeviceSpec& spec() const noexcept override { return inner_->spec(); }
  bool read(DeviceSample& sample) noexcept override;
  void write(const DeviceCommand& command) noexcept override;
  void idle() noexcept override { inner_->idle(); }

  // An outside fault happening now (a model swap), from one other thread, after the loop's
  // first tick; false when the slots are used up.
  bool markExternal(FaultKind kind) noexcept;
  // After the loop has stopped (its join orders the servo thread's writes before this).
  FaultReport report() const;

 private:
  struct Verdict {
    bool started = false, slept = false;
    std::uint64_t zeroWindowWrites = 0;  // writes where zero forces were required
    std::uint64_t writesAfter = 0;       // writes after the fault ended (the loop went on)
    // What went wrong first, from the fault's start (s); negative: it did not.
    double unboundedAt_s = -1, nonZeroAt_s = -1;
    // The longest time without a command from the fault's start to its end: a loop that
    // did not run cannot zero anything, which is a failure of its own (a missed deadline).
    double lastWrite_s = -1, longestGap_s = 0;
  };
  // Why `v` is not handled, or empty when it is.
  std::string verdictOn(const Verdict& v, const Fault& f) const;
  struct External {
    std::atomic<double> time_s{0};
    FaultKind kind = FaultKind::ModelSwap;
  };

  double now() const noexcept;
  const Fault* active(double t) noexcept;  // the scheduled fault covering t, if any
  Vec3 wanderOffset(double t) const noexcept;
  void judge(Verdict& v, const Fault& f, double t, bool zero, bool ok) noexcept;
  double zeroFrom(const Fault& f) const noexcept;  // when the forces must be zero by (detection and ramp)
  bool requiresZero(const Fault& f, double t) const noexcept;

  std::shared_ptr<Device> inner_;
  std::vector<Fault> schedule_;
  std::vector<Verdict> verdicts_;
  std::array<External, kExternalSlots> external_;
  std::array<Verdict, kExternalSlots> externalVerdicts_{};
  std::atomic<int> externalCount_{0};
  double period_s_, rampAllowance_s_;
  Clock clock_;
  double t0_ = -1;
  double lastRead_s_ = -1;
  bool lastReadStalled_ = false;
  std::size_t next_ = 0;  // first scheduled fault not yet ended
  std::array<std::array<double, 3>, 3> wanderFrequency_{}, wanderPhase_{};
  WanderAmplitude wander_;
  DeviceSample scratch_;
  FaultReport report_;
};

}  // namespace hg::device
