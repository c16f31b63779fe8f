#pragma once
// A Device whose hand the front end sets (any one thread at a time: the GUI, a script, a
// test), lock-free through a SeqLock: the servo thread reads the latest hand every tick.
// A hand not set for longer than `hold_s` counts as silence, and the servo loop's watchdog
// then trips after the spec's timeout: a front end that stops feeding the hand faults
// like a device that goes silent. No forces are displayed (write() keeps the last one
// for inspection).
#include <atomic>
#include <chrono>

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/grasp/hand_sample.hpp"
#include "hapticgrasp/servo/seqlock.hpp"

namespace hg::freecad {

class HandInputDevice final : public device::Device {
 public:
  explicit HandInputDevice(double hold_s = 0.5, device::DeviceSpec spec = defaultSpec());
  static device::DeviceSpec defaultSpec();  // "hand input", 10 N, 1 N m, 50 ms timeout

  const device::DeviceSpec& spec() const noexcept override { return spec_; }
  bool read(device::DeviceSample& sample) noexcept override;
  void write(const device::DeviceCommand& command) noexcept override;

  // One writer thread at a time. The sample's t is set here (s since construction).
  void setHand(const grasp::HandSample& hand) noexcept;
  void setSilent(bool silent) noexcept { silent_.store(silent, std::memory_order_release); }
  double lastForce() const noexcept { return lastForce_.load(std::memory_order_acquire); }

 private:
  struct Entry {
    grasp::HandSample hand;
    double setTime_s = 0;
  };
  double now() const noexcept;

  device::DeviceSpec spec_;
  double hold_s_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  servo::SeqLock<Entry> latest_;
  std::atomic<bool> silent_{false};
  std::atomic<double> lastForce_{0};
};

}  // namespace hg::freecad
