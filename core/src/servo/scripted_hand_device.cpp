#include "hapticgrasp/servo/scripted_hand_device.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hg::servo {

ScriptedHandDevice::ScriptedHandDevice(grasp::HandScript script, device::DeviceSpec spec, bool loop)
    : script_(std::move(script)), spec_(std::move(spec)), loop_(loop) {}

device::DeviceSpec ScriptedHandDevice::defaultSpec() {
  device::DeviceSpec spec;
  spec.name = "scripted hand";
  spec.forceOutput = true;
  spec.maxForce_N = 10;
  spec.maxTorque_Nm = 1;
  spec.timeout_s = 0.05;
  return spec;
}

bool ScriptedHandDevice::read(device::DeviceSample& sample) noexcept {
  const auto now = std::chrono::steady_clock::now();
  if (!started_) {
    start_ = now;
    started_ = true;
  }
  reads_.fetch_add(1, std::memory_order_acq_rel);
  const double slow = sleepOnce_s_.exchange(0, std::memory_order_acq_rel);
  if (slow > 0) {
    timespec ts;
    ts.tv_sec = static_cast<time_t>(slow);
    ts.tv_nsec = static_cast<long>((slow - static_cast<double>(ts.tv_sec)) * 1e9);
    nanosleep(&ts, nullptr);
  }
  if (silent_.load(std::memory_order_acquire)) return false;

  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const bool paused = paused_.load(std::memory_order_acquire);
  if (paused && !wasPaused_) pausedAt_ = elapsed;
  if (!paused && wasPaused_) pausedTotal_ += elapsed - pausedAt_;
  wasPaused_ = paused;
  double t = (paused ? pausedAt_ : elapsed) - pausedTotal_;
  if (loop_ && script_.duration() > 0) t = std::fmod(t, script_.duration());
  sample.hand = script_.at(t);
  sample.hand.t = t;
  sample.deviceTime_s = elapsed;
  sample.jointCount = 0;
  scriptTime_.store(t, std::memory_order_release);
  int nan = nanSamples_.load(std::memory_order_acquire);
  if (nan > 0) {
    nanSamples_.store(nan - 1, std::memory_order_release);
    sample.hand.index.x() = std::numeric_limits<double>::quiet_NaN();
  }
  return true;
}

void ScriptedHandDevice::write(const device::DeviceCommand& command) noexcept {
  writes_.fetch_add(1, std::memory_order_acq_rel);
  const double f = std::max({command.f_index.norm(), command.f_thumb.norm(), command.f_wrist.norm()});
  lastForce_.store(f, std::memory_order_release);
}

}  // namespace hg::servo
