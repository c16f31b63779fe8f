#include "hand_input_device.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hg::freecad {

HandInputDevice::HandInputDevice(double hold_s, device::DeviceSpec spec) : spec_(std::move(spec)), hold_s_(hold_s) {
  if (!(hold_s > 0 && std::isfinite(hold_s))) throw std::invalid_argument("hand hold time must be positive");
}

device::DeviceSpec HandInputDevice::defaultSpec() {
  device::DeviceSpec spec;
  spec.name = "hand input";
  spec.forceOutput = false;
  spec.maxForce_N = 10;
  spec.maxTorque_Nm = 1;
  spec.timeout_s = 0.05;
  return spec;
}

double HandInputDevice::now() const noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void HandInputDevice::setHand(const grasp::HandSample& hand) noexcept {
  Entry entry;
  entry.hand = hand;
  entry.setTime_s = now();
  entry.hand.t = entry.setTime_s;
  latest_.write(entry);
}

bool HandInputDevice::read(device::DeviceSample& sample) noexcept {
  if (silent_.load(std::memory_order_acquire)) return false;
  Entry entry;
  if (!latest_.tryRead(entry)) return false;  // nothing yet, or a write in progress
  const double t = now();
  if (t - entry.setTime_s > hold_s_) return false;  // the front end stopped feeding the hand
  sample.hand = entry.hand;
  sample.deviceTime_s = t;
  sample.jointCount = 0;
  sample.buttons = 0;
  return true;
}

void HandInputDevice::write(const device::DeviceCommand& command) noexcept {
  const double f = std::max({command.f_index.norm(), command.f_thumb.norm(), command.f_wrist.norm()});
  lastForce_.store(f, std::memory_order_release);
}

}  // namespace hg::freecad
