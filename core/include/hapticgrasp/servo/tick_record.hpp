#pragma once
// What the servo tick hands the recorder: one fixed-size record (no pointers, no heap) per tick,
// pushed into a lock-free ring that a writer thread drains (session/recorder.hpp). The
// record holds everything a replay needs to re-run the tick bit for bit (the sample as the
// device gave it, fresh or not, the measured dt, the commands applied) and everything a
// reviewer reads afterwards (forces before and after saturation, state and events, the
// moving parts' poses, passivity, timing).
//
// The ring is single-producer (the servo thread) single-consumer (the writer thread); its
// storage is allocated once, at construction, so a push never allocates. A push into a full
// ring drops the record and counts it: never silent, never blocking.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "hapticgrasp/contact/contact_report.hpp"
#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"

namespace hg::servo {

// Commands applied during a tick (TickRecord::commands), so that replay applies them too.
enum TickCommand : std::uint8_t {
  kCommandReset = 1u << 0,           // ResetGrasp
  kCommandPassivityOn = 1u << 1,     // SetPassivityController(true)
  kCommandPassivityOff = 1u << 2,    // SetPassivityController(false)
};

struct TickRecord {
  static constexpr int kMaxMoving = 8;  // moving parts recorded per tick (more: counted)
  static constexpr int kPorts = 6;      // servo::kPortCount

  std::uint64_t tick = 0;
  double time_s = 0;                    // loop time (CLOCK_MONOTONIC since start)
  double dt_s = 0;                      // measured since the previous tick
  std::uint8_t commands = 0;            // TickCommand bits applied this tick
  bool freshSample = false;             // device.read() returned a sample this tick
  bool passivityController = false;
  bool saturated = false;
  grasp::GraspState stateBefore = grasp::GraspState::Free;
  grasp::GraspState state = grasp::GraspState::Free;
  std::uint8_t watchdogFault = 0;       // WatchdogFault, active this tick
  std::uint32_t events = 0;             // GraspEvent | ServoEvent bits raised this tick
  int fingertips = 2;
  int graspedPart = -1;
  contact::ContactReport contact;       // part-to-part contact this tick (part -1: none)
  device::DeviceSample sample;          // as read (meaningful when freshSample)
  device::DeviceCommand raw;            // what the grasp asked for
  device::DeviceCommand sent;           // after passivity, saturation and the watchdog's gain
  double watchdogGain = 1;
  double energy_J[kPorts] = {};         // passivity observer per port
  double alpha_Ns_per_m[kPorts] = {};   // passivity controller damping
  // Timing of this tick: compute (without device I/O), device I/O, |period error|.
  float compute_us = 0, deviceIo_us = 0, periodError_us = 0;
  std::uint64_t scenePublications = 0;  // the scene's model swaps published when this tick began
  int movingCount = 0;                  // parts moving this tick (may exceed kMaxMoving)
  int movingPart[kMaxMoving] = {};
  grasp::PartPose movingPose[kMaxMoving];
};
// Eigen's fixed-size types are neither trivially copyable nor noexcept-marked, but they hold
// no heap: copying a record never allocates (tests count the servo thread's allocations).

// A bounded SPSC ring of TickRecords with a capacity chosen at run time (about a second or
// two of ticks), allocated at construction.
class TickRecordRing {
 public:
  explicit TickRecordRing(std::size_t capacity);  // rounded up to a power of two, >= 2

  // Producer (servo thread) only. False when full: the record is dropped and counted.
  bool push(const TickRecord& record) noexcept;
  // Consumer (writer thread) only. False when empty.
  bool pop(TickRecord& record) noexcept;

  std::size_t capacity() const noexcept { return mask_ + 1; }
  std::uint64_t pushed() const noexcept { return head_.load(std::memory_order_acquire); }
  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_acquire); }
  std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }

 private:
  std::size_t mask_;
  std::unique_ptr<TickRecord[]> items_;
  alignas(64) std::atomic<std::uint64_t> head_{0};
  alignas(64) std::atomic<std::uint64_t> tail_{0};
  alignas(64) std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace hg::servo
