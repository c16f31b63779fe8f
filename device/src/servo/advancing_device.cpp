#include "servo/advancing_device.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hg::servo {

AdvancingArmDevice::AdvancingArmDevice(std::shared_ptr<device::SimulatedMasterArm> arm, double maxStep_s,
                                       double maxGap_s)
    : arm_(std::move(arm)), maxStep_s_(maxStep_s), maxGap_s_(maxGap_s) {
  if (!arm_) throw std::invalid_argument("AdvancingArmDevice: no arm");
  if (!(maxStep_s_ > 0) || !(maxGap_s_ >= maxStep_s_))
    throw std::invalid_argument("AdvancingArmDevice: need 0 < maxStep <= maxGap");
  simTime_.store(arm_->time(), std::memory_order_release);
}

bool AdvancingArmDevice::read(device::DeviceSample& sample) noexcept {
  const auto now = std::chrono::steady_clock::now();
  if (started_) {
    const double dt = std::min(std::chrono::duration<double>(now - last_).count(), maxGap_s_);
    if (dt > 0) {
      const int steps = std::max(1, static_cast<int>(std::ceil(dt / maxStep_s_)));
      for (int i = 0; i < steps; ++i) arm_->advance(dt / steps);
    }
  }
  started_ = true;
  last_ = now;
  simTime_.store(arm_->time(), std::memory_order_release);
  return arm_->read(sample);
}

}  // namespace hg::servo
