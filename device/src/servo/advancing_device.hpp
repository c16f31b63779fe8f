#pragma once
// A SimulatedMasterArm as a servo-loop Device: each read() first advances the arm's
// simulation by the time elapsed on this adapter's own clock (steady_clock) since the
// previous read, in sub-steps of at most maxStep_s (a late tick is integrated, not
// skipped; gaps are capped at maxGap_s), then reads. So read, write and advance all run on
// the servo thread, as SimulatedMasterArm requires. Allocates nothing, never throws.
//
// The arm's simulation time is published (atomically) for other threads: simTime().
#include <atomic>
#include <chrono>
#include <memory>

#include "hapticgrasp/device/simulated_operator.hpp"

namespace hg::servo {

class AdvancingArmDevice final : public device::Device {
 public:
  explicit AdvancingArmDevice(std::shared_ptr<device::SimulatedMasterArm> arm, double maxStep_s = 0.5e-3,
                              double maxGap_s = 0.02);

  const device::DeviceSpec& spec() const noexcept override { return arm_->spec(); }
  bool read(device::DeviceSample& sample) noexcept override;
  void write(const device::DeviceCommand& command) noexcept override { arm_->write(command); }

  // The arm's simulation time (s), safe to read from any thread.
  double simTime() const noexcept { return simTime_.load(std::memory_order_acquire); }

 private:
  std::shared_ptr<device::SimulatedMasterArm> arm_;
  double maxStep_s_, maxGap_s_;
  bool started_ = false;
  std::chrono::steady_clock::time_point last_{};
  std::atomic<double> simTime_{0.0};
};

}  // namespace hg::servo
