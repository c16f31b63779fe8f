#pragma once
// A Device that replays a grasp::HandScript by wall time (CLOCK_MONOTONIC from the first
// read()), for benchmarks, demos and tests of the servo loop. Faults can be injected from
// any thread (atomics): silence, NaN samples, one slow read.
#include <atomic>
#include <chrono>

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/grasp/hand_script.hpp"

namespace hg::servo {

class ScriptedHandDevice : public device::Device {
 public:
  // `loop`: replay the script over and over (its last key should match its first).
  ScriptedHandDevice(grasp::HandScript script, device::DeviceSpec spec = defaultSpec(), bool loop = false);

  static device::DeviceSpec defaultSpec();  // "scripted hand", 10 N, 1 N m, 50 ms timeout

  const device::DeviceSpec& spec() const noexcept override { return spec_; }
  bool read(device::DeviceSample& sample) noexcept override;
  void write(const device::DeviceCommand& command) noexcept override;

  // Fault injection (any thread).
  void setSilent(bool silent) noexcept { silent_.store(silent, std::memory_order_release); }
  void injectNaN(int samples) noexcept { nanSamples_.store(samples, std::memory_order_release); }
  void sleepOnce(double seconds) noexcept { sleepOnce_s_.store(seconds, std::memory_order_release); }
  // Freeze script time (the hand holds still; samples keep coming).
  void setPaused(bool paused) noexcept { paused_.store(paused, std::memory_order_release); }

  // Script time of the last sample, and counts (any thread).
  double scriptTime() const noexcept { return scriptTime_.load(std::memory_order_acquire); }
  long reads() const noexcept { return reads_.load(std::memory_order_acquire); }
  long writes() const noexcept { return writes_.load(std::memory_order_acquire); }
  // The last command written, as magnitudes (any thread): max of the three forces.
  double lastForce() const noexcept { return lastForce_.load(std::memory_order_acquire); }

 private:
  grasp::HandScript script_;
  device::DeviceSpec spec_;
  bool loop_;
  bool started_ = false;
  std::chrono::steady_clock::time_point start_;
  double pausedAt_ = 0, pausedTotal_ = 0;
  bool wasPaused_ = false;
  std::atomic<bool> silent_{false}, paused_{false};
  std::atomic<int> nanSamples_{0};
  std::atomic<double> sleepOnce_s_{0};
  std::atomic<double> scriptTime_{0};
  std::atomic<long> reads_{0}, writes_{0};
  std::atomic<double> lastForce_{0};
};

}  // namespace hg::servo
