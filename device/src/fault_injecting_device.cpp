#include "hapticgrasp/device/fault_injecting_device.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace hg::device {
namespace {

// Faults after which the loop must have zeroed the forces, and how long it may take first.
bool zeroes(FaultKind k) {
  return k == FaultKind::Silence || k == FaultKind::Unplug || k == FaultKind::NaNSample || k == FaultKind::InfSample;
}

bool finite(const DeviceCommand& c) {
  bool ok = c.f_index.allFinite() && c.f_thumb.allFinite() && c.f_wrist.allFinite() && c.m_wrist.allFinite() &&
            std::isfinite(c.f_grasp);
  for (const Vec3& f : c.f_extra) ok = ok && f.allFinite();
  return ok;
}

bool zero(const DeviceCommand& c) {
  bool z = c.f_index.isZero(0) && c.f_thumb.isZero(0) && c.f_wrist.isZero(0) && c.m_wrist.isZero(0) && c.f_grasp == 0;
  for (const Vec3& f : c.f_extra) z = z && f.isZero(0);
  return z;
}

bool bounded(const DeviceCommand& c, const DeviceSpec& s) {
  const double f = s.maxForce_N * (1 + 1e-9), m = s.maxTorque_Nm * (1 + 1e-9);
  bool ok = c.f_index.norm() <= f && c.f_thumb.norm() <= f && c.f_wrist.norm() <= f && c.m_wrist.norm() <= m &&
            std::abs(c.f_grasp) <= f;
  for (const Vec3& e : c.f_extra) ok = ok && e.norm() <= f;
  return ok;
}

void sleepFor(double seconds) noexcept {
  timespec ts{static_cast<time_t>(seconds), static_cast<long>(std::fmod(seconds, 1.0) * 1e9)};
  while (nanosleep(&ts, &ts) != 0) {
  }
}

void spoil(DeviceSample& s, double value) noexcept {
  s.hand.index = Vec3::Constant(value);
  s.hand.thumb.x() = value;
}

}  // namespace

const char* toString(FaultKind kind) {
  switch (kind) {
    case FaultKind::Silence: return "silence";
    case FaultKind::NaNSample: return "nan";
    case FaultKind::InfSample: return "inf";
    case FaultKind::Stall: return "stall";
    case FaultKind::Unplug: return "unplug";
    case FaultKind::ModelSwap: return "model swap";
  }
  return "?";
}

std::uint64_t FaultReport::totalInjected() const {
  std::uint64_t n = 0;
  for (auto k : injected) n += k;
  return n;
}

std::uint64_t FaultReport::totalHandled() const {
  std::uint64_t n = 0;
  for (auto k : handled) n += k;
  return n;
}

std::vector<Fault> randomFaults(double seconds, double perMinute, std::mt19937_64& random, int firstKind) {
  std::uniform_real_distribution<double> unit(0, 1);
  const auto between = [&](double a, double b) { return a + (b - a) * unit(random); };
  constexpr FaultKind kinds[] = {FaultKind::Silence, FaultKind::NaNSample, FaultKind::InfSample, FaultKind::Stall,
                                 FaultKind::Unplug};
  const double meanGap_s = 60.0 / std::max(perMinute, 1e-3);
  std::vector<Fault> faults;
  // The first second is left alone: the hand reaches the part.
  for (double t = 1.0 + between(0, meanGap_s);; t += 0.5 + between(0, 2 * meanGap_s)) {
    Fault f;
    f.kind = kinds[(static_cast<std::size_t>(firstKind) + faults.size()) % std::size(kinds)];  // every kind in turn, at random times
    f.start_s = t;
    switch (f.kind) {
      case FaultKind::Silence: f.duration_s = between(0.1, 0.5); break;
      case FaultKind::NaNSample:
      case FaultKind::InfSample: f.duration_s = between(0.02, 0.1); break;
      case FaultKind::Stall: f.duration_s = between(0.005, 0.05); break;
      default: f.duration_s = between(0.5, 2.0); break;
    }
    if (f.start_s + f.duration_s > seconds) break;
    faults.push_back(f);
    t += f.duration_s;
  }
  return faults;
}

FaultInjectingDevice::FaultInjectingDevice(std::shared_ptr<Device> inner, std::vector<Fault> schedule, double rate_hz,
                                           double rampAllowance_s, std::uint64_t wanderSeed, WanderAmplitude wander,
                                           Clock clock)
    : inner_(std::move(inner)),
      schedule_(std::move(schedule)),
      verdicts_(schedule_.size()),
      period_s_(1.0 / rate_hz),
      rampAllowance_s_(rampAllowance_s),
      clock_(std::move(clock)),
      wander_(wander) {
  if (!inner_) throw std::invalid_argument("fault injection: no device to wrap");
  for (std::size_t i = 1; i < schedule_.size(); ++i)
    if (schedule_[i].start_s < schedule_[i - 1].start_s + schedule_[i - 1].duration_s)
      throw std::invalid_argument("fault injection: faults must be sorted and apart");
  std::mt19937_64 random(wanderSeed);
  std::uniform_real_distribution<double> unit(0, 1);
  for (auto& axis : wanderFrequency_)
    for (double& f : axis) f = wander.minFrequency_Hz + (wander.maxFrequency_Hz - wander.minFrequency_Hz) * unit(random);
  for (auto& axis : wanderPhase_)
    for (double& p : axis) p = 2 * std::numbers::pi * unit(random);
}

double FaultInjectingDevice::now() const noexcept {
  if (clock_) return clock_();
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

const Fault* FaultInjectingDevice::active(double t) noexcept {
  while (next_ < schedule_.size() && t >= schedule_[next_].start_s + schedule_[next_].duration_s) ++next_;
  if (next_ < schedule_.size() && t >= schedule_[next_].start_s) {
    if (!verdicts_[next_].started) {
      verdicts_[next_].started = true;
      ++report_.injected[static_cast<int>(schedule_[next_].kind)];
    }
    return &schedule_[next_];
  }
  return nullptr;
}

Vec3 FaultInjectingDevice::wanderOffset(double t) const noexcept {
  Vec3 offset;
  for (int axis = 0; axis < 3; ++axis) {
    double s = 0;
    for (int k = 0; k < 3; ++k)
      s += std::sin(2 * std::numbers::pi * wanderFrequency_[axis][k] * t + wanderPhase_[axis][k]);
    offset[axis] = wander_.amplitude_m[axis] * s / 3;
  }
  return offset;
}

bool FaultInjectingDevice::read(DeviceSample& sample) noexcept {
  const double clockNow = now();
  if (t0_ < 0) t0_ = clockNow;
  const double t = clockNow - t0_;
  if (lastRead_s_ >= 0 && !lastReadStalled_)
    report_.maxPeriodErrUnstalled_us = std::max(report_.maxPeriodErrUnstalled_us, 1e6 * std::abs(t - lastRead_s_ - period_s_));
  lastRead_s_ = t;
  lastReadStalled_ = false;
  const Fault* f = active(t);
  if (f && f->kind == FaultKind::Unplug) return false;  // gone: nothing is read from it
  if (f && f->kind == FaultKind::Silence) {
    inner_->read(scratch_);  // alive, keeps its own time, but nothing new reaches the loop
    return false;
  }
  if (f && f->kind == FaultKind::Stall && !verdicts_[static_cast<std::size_t>(f - schedule_.data())].slept) {
    verdicts_[static_cast<std::size_t>(f - schedule_.data())].slept = true;
    sleepFor(f->duration_s);  // a read that blocks once, as a USB device that hangs does
    lastReadStalled_ = true;
  }
  const bool fresh = inner_->read(sample);
  if (!fresh) return false;
  const Vec3 offset = wanderOffset(t);
  sample.hand.index += offset;
  sample.hand.thumb += offset;
  sample.hand.wrist += offset;
  for (Vec3& e : sample.hand.extra) e += offset;
  if (f && f->kind == FaultKind::NaNSample) spoil(sample, std::numeric_limits<double>::quiet_NaN());
  if (f && f->kind == FaultKind::InfSample) spoil(sample, std::numeric_limits<double>::infinity());
  return true;
}

double FaultInjectingDevice::zeroFrom(const Fault& f) const noexcept {
  const bool silent = f.kind == FaultKind::Silence || f.kind == FaultKind::Unplug;
  return f.start_s + (silent ? inner_->spec().timeout_s : 0.0) + rampAllowance_s_;
}

bool FaultInjectingDevice::requiresZero(const Fault& f, double t) const noexcept {
  return zeroes(f.kind) && t >= zeroFrom(f) && t < f.start_s + f.duration_s;
}

void FaultInjectingDevice::judge(Verdict& v, const Fault& f, double t, bool isZero, bool ok) noexcept {
  if (t < f.start_s) return;
  if (!ok && v.unboundedAt_s < 0) v.unboundedAt_s = t - f.start_s;
  if (t >= f.start_s + f.duration_s) {
    if (v.writesAfter++ == 0) v.longestGap_s = std::max(v.longestGap_s, f.start_s + f.duration_s - std::max(v.lastWrite_s, f.start_s));
    return;
  }
  v.longestGap_s = std::max(v.longestGap_s, t - std::max(v.lastWrite_s, f.start_s));
  v.lastWrite_s = t;
  if (requiresZero(f, t)) {
    ++v.zeroWindowWrites;
    if (!isZero && v.nonZeroAt_s < 0) v.nonZeroAt_s = t - f.start_s;
  }
}

void FaultInjectingDevice::write(const DeviceCommand& command) noexcept {
  const double t = lastRead_s_;  // the tick's time: the loop reads, then writes
  const bool isFinite = finite(command), isBounded = isFinite && bounded(command, inner_->spec());
  if (!isFinite) ++report_.nanOutputs;
  if (isFinite && !isBounded) ++report_.unboundedOutputs;
  const bool isZero = isFinite && zero(command);
  // The scheduled faults under way or just over (judged until a later one starts).
  for (std::size_t i = next_ > 0 ? next_ - 1 : 0; i < std::min(next_ + 1, schedule_.size()); ++i)
    if (verdicts_[i].started) judge(verdicts_[i], schedule_[i], t, isZero, isBounded);
  const int external = std::min(externalCount_.load(std::memory_order_acquire), kExternalSlots);
  for (int i = std::max(0, external - 2); i < external; ++i) {
    Fault f{external_[static_cast<std::size_t>(i)].kind, external_[static_cast<std::size_t>(i)].time_s.load(std::memory_order_relaxed) - t0_, 0};
    judge(externalVerdicts_[static_cast<std::size_t>(i)], f, t, isZero, isBounded);
  }
  const Fault* f = next_ < schedule_.size() && t >= schedule_[next_].start_s ? &schedule_[next_] : nullptr;
  if (f && f->kind == FaultKind::Unplug && t < f->start_s + f->duration_s) {
    ++report_.writesDropped;
    return;
  }
  inner_->write(command);
}

bool FaultInjectingDevice::markExternal(FaultKind kind) noexcept {
  const int i = externalCount_.load(std::memory_order_relaxed);
  if (i >= kExternalSlots) return false;
  external_[static_cast<std::size_t>(i)].kind = kind;
  external_[static_cast<std::size_t>(i)].time_s.store(now(), std::memory_order_relaxed);
  externalCount_.store(i + 1, std::memory_order_release);
  return true;
}

std::string FaultInjectingDevice::verdictOn(const Verdict& v, const Fault& f) const {
  const auto ms = [](double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f ms", 1e3 * s);
    return std::string(text);
  };
  if (v.unboundedAt_s >= 0) return "a command beyond the device's spec " + ms(v.unboundedAt_s) + " into it";
  if (v.nonZeroAt_s >= 0) return "forces not zero " + ms(v.nonZeroAt_s) + " into it";
  const double window_s = f.start_s + f.duration_s - zeroFrom(f);
  // A fault long enough to need zero forces must have seen some.
  if (zeroes(f.kind) && window_s > 0 && v.zeroWindowWrites == 0)
    return "no command in its last " + ms(window_s) + ", where forces must be zero: the loop's longest gap " +
           ms(v.longestGap_s);
  if (v.writesAfter == 0) return "no command after it";
  return {};
}

FaultReport FaultInjectingDevice::report() const {
  FaultReport r = report_;
  const auto count = [&](const Verdict& v, const Fault& f) {
    std::string why = verdictOn(v, f);
    if (why.empty())
      ++r.handled[static_cast<int>(f.kind)];
    else
      r.unhandled.push_back({f, std::move(why)});
  };
  for (std::size_t i = 0; i < schedule_.size(); ++i)
    if (verdicts_[i].started) count(verdicts_[i], schedule_[i]);
  const int external = std::min(externalCount_.load(std::memory_order_acquire), kExternalSlots);
  for (int i = 0; i < external; ++i) {
    const External& e = external_[static_cast<std::size_t>(i)];
    ++r.injected[static_cast<int>(e.kind)];
    count(externalVerdicts_[static_cast<std::size_t>(i)], Fault{e.kind, e.time_s.load(std::memory_order_relaxed) - t0_, 0});
  }
  return r;
}

}  // namespace hg::device
