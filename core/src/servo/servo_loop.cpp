#include "hapticgrasp/servo/servo_loop.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>


namespace hg::servo {
namespace {

std::int64_t nowNs() noexcept {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleepUntil(std::int64_t deadlineNs) noexcept {
  timespec ts;
  ts.tv_sec = static_cast<time_t>(deadlineNs / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(deadlineNs % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

std::string errorText(int code) {
  std::string text;
  switch (code) {
    case EPERM: text = "EPERM"; break;
    case ENOMEM: text = "ENOMEM"; break;
    case EINVAL: text = "EINVAL"; break;
    default: text = "errno " + std::to_string(code); break;
  }
  text.append(": ");
  text.append(std::strerror(code));
  return text;
}

// Clamps |v| to `limit` keeping the direction; non-finite vectors become zero.
bool clampNorm(Vec3& v, double limit) noexcept {
  if (!v.allFinite()) {
    v.setZero();
    return true;
  }
  const double n = v.norm();
  if (n > limit) {
    v *= limit / n;
    return true;
  }
  return false;
}

device::DeviceCommand scaled(const device::DeviceCommand& c, double gain) noexcept {
  device::DeviceCommand out;
  out.f_index = gain * c.f_index;
  out.f_thumb = gain * c.f_thumb;
  out.f_wrist = gain * c.f_wrist;
  out.m_wrist = gain * c.m_wrist;
  out.f_grasp = gain * c.f_grasp;
  for (int k = 0; k < grasp::HandSample::kMaxFingertips - 2; ++k) out.f_extra[k] = gain * c.f_extra[k];
  return out;
}

}  // namespace

const char* toString(WatchdogFault fault) {
  switch (fault) {
    case WatchdogFault::None: return "none";
    case WatchdogFault::Silent: return "silent";
    case WatchdogFault::NonFinite: return "non-finite sample";
  }
  return "?";
}

std::string eventsText(std::uint32_t events) {
  std::string text;
  const auto add = [&](const char* name) {
    if (!text.empty()) text += ", ";
    text += name;
  };
  for (int b = 0; b < grasp::kEventCount; ++b)
    if (events & (1u << b)) add(grasp::eventName(static_cast<grasp::GraspEvent>(1u << b)));
  if (events & kWatchdogTrip) add("watchdog trip");
  if (events & kWatchdogClear) add("watchdog clear");
  if (events & kGraspReset) add("grasp reset");
  return text;
}

int servoCpu() noexcept {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) != 0 || CPU_COUNT(&set) < 2) return -1;
  for (int cpu = CPU_SETSIZE - 1; cpu >= 0; --cpu)
    if (CPU_ISSET(cpu, &set)) return cpu;
  return -1;
}

void ServoConfig::validate() const {
  if (!(rate_hz >= 50 && rate_hz <= 10000)) throw std::invalid_argument("servo rate must be in [50, 10000] Hz");
  if (fifoPriority < 1 || fifoPriority > 99) throw std::invalid_argument("SCHED_FIFO priority must be in [1, 99]");
  if (!(watchdogRamp_s > 0 && watchdogRamp_s <= 1)) throw std::invalid_argument("watchdog ramp must be in (0, 1] s");
  if (cpu >= CPU_SETSIZE) throw std::invalid_argument("no CPU " + std::to_string(cpu));
}

std::uint32_t SnapshotReader::eventsSinceLastRead(const ServoSnapshot& s, bool* lost) noexcept {
  std::uint32_t bits = 0;
  bool missed = false;
  if (s.eventCount > seen_) {
    const std::uint64_t oldest = s.eventCount > ServoSnapshot::kEventLog ? s.eventCount - ServoSnapshot::kEventLog : 0;
    missed = seen_ < oldest;
    for (std::uint64_t i = std::max(seen_, oldest); i < s.eventCount; ++i) bits |= s.eventLog[i % ServoSnapshot::kEventLog].events;
    if (missed)
      for (int b = 0; b < 32; ++b)
        if (s.eventTotals[b] > totals_[b]) bits |= 1u << b;
  }
  seen_ = s.eventCount;
  std::copy(std::begin(s.eventTotals), std::end(s.eventTotals), std::begin(totals_));
  if (lost) *lost = missed;
  return bits;
}

namespace {
std::unique_ptr<GraspEngine> twoFinger(const grasp::ScenePtr& scene, const grasp::GraspParameters& parameters) {
  if (!scene) throw std::invalid_argument("servo loop: no scene");
  return std::make_unique<TwoFingerEngine>(scene, parameters);
}
}  // namespace

ServoLoop::ServoLoop(std::shared_ptr<device::Device> device, grasp::ScenePtr scene,
                     const grasp::GraspParameters& parameters, const ServoConfig& config)
    : ServoLoop(std::move(device), twoFinger(scene, parameters), config) {}

ServoLoop::ServoLoop(std::shared_ptr<device::Device> device, std::unique_ptr<GraspEngine> engine,
                     const ServoConfig& config)
    : device_(std::move(device)), engine_(std::move(engine)), config_(config) {
  if (!device_) throw std::invalid_argument("servo loop: no device");
  if (!engine_) throw std::invalid_argument("servo loop: no grasp method");
  if (engine_->fingertips() > device_->spec().fingertips)
    throw std::invalid_argument("servo loop: the " + std::string(engine_->name()) + " method needs " +
                                std::to_string(engine_->fingertips()) + " fingertips, the device '" +
                                device_->spec().name + "' reads " + std::to_string(device_->spec().fingertips));
  config_.validate();
  passivityOn_ = config_.passivityController;
  snap_.method = engine_->name();
  snap_.fingertips = engine_->fingertips();
  snap_.partCount = static_cast<int>(engine_->partCount());
}

ServoLoop::~ServoLoop() { stop(); }

void ServoLoop::start() {
  if (started_.exchange(true)) throw std::logic_error("servo loop: start() called twice");
  running_.store(true, std::memory_order_release);
  try {
    thread_ = std::thread([this] { run(); });
  } catch (...) {
    running_.store(false, std::memory_order_release);
    throw;
  }
  ready_.wait(false, std::memory_order_acquire);
}

void ServoLoop::stop() noexcept {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

TimingSummary ServoLoop::timing() const noexcept {
  if (!running()) return final_;
  ServoSnapshot s;
  return read(s) ? s.timing : TimingSummary{};
}

void ServoLoop::run() noexcept {
  // --- Setup (may allocate: before the first tick and the allocation baseline).
  if (config_.realtime) {
    sched_param param{};
    param.sched_priority = config_.fifoPriority;
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    scheduler_ = rc == 0 ? "SCHED_FIFO" : "SCHED_OTHER (" + errorText(rc) + ")";
    // Everything mapped now is locked and made resident (the loop's state, its stack, the
    // models); what is mapped later is locked as it is first touched (MCL_ONFAULT), not
    // populated whole at mmap time: with plain MCL_FUTURE, FreeCAD's model builders ran 5x
    // slower beside the servo (measured: five 1,030-face plates in 188 s instead of 37 s).
    locked_ = mlockall(MCL_CURRENT) == 0;  // undone at exit even if the second call fails
    if (!locked_)
      memoryLock_ = "none (" + errorText(errno) + ")";
    else if (mlockall(MCL_FUTURE | MCL_ONFAULT) == 0)
      memoryLock_ = "mlockall";
    else
      memoryLock_ = "current pages only (" + errorText(errno) + ")";
  } else {
    scheduler_ = "SCHED_OTHER (not requested)";
    memoryLock_ = "none (not requested)";
  }
  if (config_.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(config_.cpu, &set);
    const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    affinity_ = rc == 0 ? "cpu " + std::to_string(config_.cpu) : "any (" + errorText(rc) + ")";
  } else {
    affinity_ = "any (not requested)";
  }
  {  // Touch the stack the tick will use (the snapshot copies are ~10 KB each).
    volatile char stack[128 * 1024];
    for (std::size_t i = 0; i < sizeof(stack); i += 4096) stack[i] = 0;
  }
  const std::int64_t period = std::llround(1e9 / config_.rate_hz);
  snap_.timing.target_hz = config_.rate_hz;
  ready_.store(true, std::memory_order_release);
  ready_.notify_all();

  allocationBase_ = config_.allocationCounter ? config_.allocationCounter() : 0;
  const std::int64_t start = nowNs();
  std::int64_t next = start, previous = start;
  // --- The loop: no allocation, no lock, no I/O from here on.
  while (!stop_.load(std::memory_order_acquire)) {
    sleepUntil(next);
    if (stop_.load(std::memory_order_acquire)) break;
    const std::int64_t wake = nowNs();
    const double t = 1e-9 * static_cast<double>(wake - start);
    const double dt = ticks_ ? 1e-9 * static_cast<double>(wake - previous) : 0.0;
    previous = wake;
    lastPeriodError_s_ = ticks_ ? std::abs(dt - 1e-9 * static_cast<double>(period)) : 0.0;
    if (ticks_) periodError_.add(lastPeriodError_s_);
    tick(t, dt);
    next += period;
    const std::int64_t end = nowNs();
    if (end >= next) {  // missed: skip to the next deadline after now, do not catch up
      const std::int64_t skipped = (end - next) / period + 1;
      next += skipped * period;
      overruns_ += static_cast<std::uint64_t>(skipped);
      ++lateTicks_;
    }
  }
  // --- Shutdown.
  device_->idle();
  snap_.sent = device::DeviceCommand{};
  snap_.timing = final_ = timingSummary();
  publish();
  if (locked_) munlockall();
  running_.store(false, std::memory_order_release);
}

TimingSummary ServoLoop::timingSummary() const noexcept {
  TimingSummary s;
  s.target_hz = config_.rate_hz;
  s.ticks = ticks_;
  s.overruns = overruns_;
  s.lateTicks = lateTicks_;
  s.achieved_hz = ticks_ > 1 && lastTick_s_ > firstTick_s_ ? (ticks_ - 1) / (lastTick_s_ - firstTick_s_) : 0;
  s.periodError = periodError_.summary();
  s.compute = compute_.summary();
  s.deviceIo = deviceIo_.summary();
  return s;
}

void ServoLoop::record(std::shared_ptr<TickRecordRing> ring) {
  if (started_.load()) throw std::logic_error("servo loop: record() after start()");
  records_ = std::move(ring);
}

void ServoLoop::step(double t, double dt) {
  if (started_.load()) throw std::logic_error("servo loop: step() on a started loop (its thread ticks it)");
  tick(t, dt);
}

// One tick: the named stages in order. While the watchdog holds a fault, the grasp does
// not step and the held command ramps down; otherwise a good sample steps the grasp and a
// missing one holds the last command.
void ServoLoop::tick(double t, double dt) noexcept {
  TickState s;
  s.t = t;
  s.dt = dt;
  s.computeStart_ns = nowNs();
  s.before = engine_->state();
  if (records_) s.publications = engine_->parts().publications();
  drainCommands(s);
  readDevice(s);
  watchdog(s);
  if (snap_.watchdog.fault == WatchdogFault::None && s.good) {
    graspStep(s);
    device::DeviceCommand c = snap_.raw;
    passivity(c);
    saturate(c);
    lastOut_ = c;
  } else {
    for (int p = 0; p < kPortCount; ++p) snap_.alpha_Ns_per_m[p] = 0;
  }
  outputGain(s);
  writeDevice(s);
  publishSnapshot(s);
  pushRecord(s);
}

// GUI commands, applied before the sample is read.
void ServoLoop::drainCommands(TickState& s) noexcept {
  ServoCommand command;
  while (commands_.pop(command)) {
    switch (command.kind) {
      case ServoCommand::Kind::ResetGrasp:
        engine_->reset();
        logMove(-1, {});
        s.events |= kGraspReset;
        s.commands |= kCommandReset;
        break;
      case ServoCommand::Kind::SetPassivityController:
        passivityOn_ = command.on;
        s.commands |= command.on ? kCommandPassivityOn : kCommandPassivityOff;
        break;
      case ServoCommand::Kind::Stop: stop_.store(true, std::memory_order_release); break;
    }
  }
}

void ServoLoop::readDevice(TickState& s) noexcept {
  pendingDt_ += s.dt;
  sampleDt_ += s.dt;
  const std::int64_t readStart = nowNs();
  s.fresh = device_->read(sample_);
  s.io_ns += nowNs() - readStart;
  s.good = s.fresh && sample_.hand.finite();
  if (s.good) lastFresh_s_ = s.t;
  snap_.watchdog.silence_s = s.t - lastFresh_s_;
}

// Trips on a non-finite sample or silence past the device's timeout: the grasp is reset at
// once and the command the operator feels ramps down from where it is. Clears on a fresh
// finite sample, the grasp restarting as on a first sample.
void ServoLoop::watchdog(TickState& s) noexcept {
  WatchdogStatus& wd = snap_.watchdog;
  WatchdogFault fault = WatchdogFault::None;
  double rampOrigin = s.t;
  if (s.fresh && !s.good) {
    fault = WatchdogFault::NonFinite;
  } else if (!s.fresh && wd.silence_s > device_->spec().timeout_s) {
    fault = WatchdogFault::Silent;
    rampOrigin = lastFresh_s_ + device_->spec().timeout_s;  // the ramp starts when the timeout expired
  }
  if (fault != WatchdogFault::None && wd.fault == WatchdogFault::None) {
    wd.fault = wd.lastFault = fault;
    wd.faultTime_s = s.t;
    ++wd.trips;
    s.events |= kWatchdogTrip;
    faultStart_s_ = rampOrigin;
    held_ = snap_.sent;  // what the operator feels now; ramps down from here
    gain_ = 1;           // held_ already carries the current gain
    engine_->reset();    // FREE, every part at its initial pose
    logMove(-1, {});
    snap_.graspedPart = -1;
    for (PassivityPort& p : ports_) p.reset();
  }
  if (s.good && wd.fault != WatchdogFault::None) {
    wd.fault = WatchdogFault::None;
    wd.clearTime_s = s.t;
    s.events |= kWatchdogClear;
    pendingDt_ = 0;
    sampleDt_ = 0;
    for (PassivityPort& p : ports_) p.reset();
    lastOut_ = device::DeviceCommand{};
    gain_ = 0;  // and ramps back up
  }
}

// The grasp method on the fresh sample, with the time since its previous step: in steps
// of at most kMaxGraspStep_s when that time is longer (a late tick, samples that did not
// come), the hand between the two samples; what any step raised is raised.
void ServoLoop::graspStep(TickState& s) noexcept {
  const grasp::HandSample from = lastHand_;
  const double gap = haveHand_ ? pendingDt_ : 0.0;
  lastHand_ = sample_.hand;
  haveHand_ = true;
  pendingDt_ = 0;
  // Clamped as a double: a replayed recording's dt may be anything (NaN, 1e300), and the
  // engines refuse a non-finite one themselves.
  const double wanted = std::ceil(gap / kMaxGraspStep_s);
  const int steps = wanted > kMaxGraspSubsteps ? kMaxGraspSubsteps : wanted > 1 ? static_cast<int>(wanted) : 1;
  EngineStep g;
  for (int k = 1; k <= steps; ++k) {
    const double f = static_cast<double>(k) / steps;
    g = engine_->step(k == steps ? lastHand_ : grasp::between(from, lastHand_, f), gap / steps);
    s.events |= g.events;
  }
  snap_.raw = g.command;
  snap_.graspedPart = g.graspedPart;
  snap_.contact = g.contact;
}

// Passivity observer (always) and controller (when on), per port.
void ServoLoop::passivity(device::DeviceCommand& c) noexcept {
  const device::DeviceCommand& raw = snap_.raw;
  const double sdt = sampleDt_;
  sampleDt_ = 0;
  const double bMax = device_->spec().maxDamping_Ns_per_m;
  double* alpha = snap_.alpha_Ns_per_m;
  alpha[kIndexPort] = ports_[kIndexPort].update(lastHand_.index, sdt, raw.f_index, passivityOn_, bMax, c.f_index);
  alpha[kThumbPort] = ports_[kThumbPort].update(lastHand_.thumb, sdt, raw.f_thumb, passivityOn_, bMax, c.f_thumb);
  alpha[kWristPort] = ports_[kWristPort].update(lastHand_.wrist, sdt, raw.f_wrist, passivityOn_, bMax, c.f_wrist);
  for (int k = 2; k < snap_.fingertips; ++k) {
    const int port = kExtraPort + k - 2;
    alpha[port] = ports_[port].update(lastHand_.fingertip(k), sdt, raw.fingertipForce(k), passivityOn_, bMax,
                                      c.fingertipForce(k));
  }
}

// To the device's spec: magnitudes clamped, directions kept.
void ServoLoop::saturate(device::DeviceCommand& c) noexcept {
  const device::DeviceSpec& spec = device_->spec();
  bool saturated = false;
  saturated |= clampNorm(c.f_index, spec.maxForce_N);
  saturated |= clampNorm(c.f_thumb, spec.maxForce_N);
  for (Vec3& f : c.f_extra) saturated |= clampNorm(f, spec.maxForce_N);
  saturated |= clampNorm(c.f_wrist, spec.maxForce_N);
  saturated |= clampNorm(c.m_wrist, spec.maxTorque_Nm);
  if (!std::isfinite(c.f_grasp) || c.f_grasp < 0) c.f_grasp = 0;
  if (c.f_grasp > spec.maxForce_N) {
    c.f_grasp = spec.maxForce_N;
    saturated = true;
  }
  snap_.saturated = saturated;
}

// Under a fault the held command ramps to zero; otherwise the last command (held when no
// fresh sample came) with a gain ramping back to one after a fault.
void ServoLoop::outputGain(TickState& s) noexcept {
  if (snap_.watchdog.fault != WatchdogFault::None) {
    gain_ = std::clamp(1.0 - (s.t - faultStart_s_) / config_.watchdogRamp_s, 0.0, gain_);
    s.out = scaled(held_, gain_);
    snap_.raw = device::DeviceCommand{};
  } else {
    gain_ = std::min(1.0, gain_ + s.dt / config_.watchdogRamp_s);
    s.out = scaled(lastOut_, gain_);
  }
}

void ServoLoop::writeDevice(TickState& s) noexcept {
  const std::int64_t writeStart = nowNs();
  device_->write(s.out);
  const std::int64_t writeEnd = nowNs();
  s.io_ns += writeEnd - writeStart;
  deviceIo_.add(1e-9 * static_cast<double>(s.io_ns));
  compute_.add(1e-9 * static_cast<double>(writeEnd - s.computeStart_ns - s.io_ns));
}

void ServoLoop::publishSnapshot(TickState& s) noexcept {
  ++ticks_;
  if (ticks_ == 1) firstTick_s_ = s.t;
  lastTick_s_ = s.t;
  snap_.watchdog.gain = gain_;
  snap_.tick = snap_.tickMid = snap_.tickEnd = ticks_;
  snap_.time_s = s.t;
  snap_.dt_s = s.dt;
  snap_.state = engine_->state();
  snap_.freshSample = s.fresh;
  snap_.passivityController = passivityOn_;
  snap_.hand = lastHand_;
  snap_.sent = s.out;
  for (int p = 0; p < kPortCount; ++p) snap_.energy_J[p] = ports_[p].energy();
  snap_.events = s.events;
  if (s.events != 0 || snap_.state != s.before) {
    EventRecord& r = snap_.eventLog[snap_.eventCount % ServoSnapshot::kEventLog];
    r = {ticks_, s.t, s.events, s.before, snap_.state};
    ++snap_.eventCount;
    for (int b = 0; b < 32; ++b)
      if (s.events & (1u << b)) ++snap_.eventTotals[b];
  }
  publishPoses();
  if (config_.allocationCounter) snap_.allocations = config_.allocationCounter() - allocationBase_;
  if ((ticks_ & 63) == 1) snap_.timing = timingSummary();  // every 64 ticks: the histograms cost a scan
  publish();
}

// One fixed-size record into the recorder's ring; a full ring drops it (and counts it).
void ServoLoop::pushRecord(const TickState& s) noexcept {
  if (!records_) return;
  TickRecord& r = record_;
  r.tick = ticks_;
  r.time_s = s.t;
  r.dt_s = s.dt;
  r.commands = s.commands;
  r.freshSample = s.fresh;
  r.passivityController = passivityOn_;
  r.saturated = snap_.saturated;
  r.stateBefore = s.before;
  r.state = snap_.state;
  r.watchdogFault = static_cast<std::uint8_t>(snap_.watchdog.fault);
  r.events = s.events;
  r.fingertips = snap_.fingertips;
  r.graspedPart = snap_.graspedPart;
  r.contact = snap_.contact;
  if (s.fresh) r.sample = sample_;
  r.raw = snap_.raw;
  r.sent = s.out;
  r.watchdogGain = gain_;
  std::copy(std::begin(snap_.energy_J), std::end(snap_.energy_J), r.energy_J);
  std::copy(std::begin(snap_.alpha_Ns_per_m), std::end(snap_.alpha_Ns_per_m), r.alpha_Ns_per_m);
  const std::int64_t now = nowNs();
  r.compute_us = static_cast<float>(1e-3 * static_cast<double>(now - s.computeStart_ns - s.io_ns));
  r.deviceIo_us = static_cast<float>(1e-3 * static_cast<double>(s.io_ns));
  r.periodError_us = static_cast<float>(1e6 * lastPeriodError_s_);
  r.scenePublications = s.publications;
  r.movingCount = snap_.movingCount;
  const int n = std::min(snap_.movingCount, TickRecord::kMaxMoving);
  for (int k = 0; k < n; ++k) {
    r.movingPart[k] = snap_.moving[k].part;
    r.movingPose[k] = snap_.moving[k].pose;
  }
  records_->push(r);
}

void ServoLoop::publish() noexcept { snapshot_.write(snap_); }

void ServoLoop::logMove(int part, const grasp::PartPose& pose) noexcept {
  snap_.moveLog[snap_.moveCount % ServoSnapshot::kMoveLog] = {part, pose};
  ++snap_.moveCount;
  if (part < 0) wasMovingCount_ = 0;  // a reset: nothing moves any more, nothing to put down
}

// The moving parts' poses this tick; a part that moved last tick and no longer does was put
// down: where it stands goes to the log, once.
void ServoLoop::publishPoses() noexcept {
  const auto poses = engine_->poses();
  const auto moving = engine_->moving();
  for (int k = 0; k < wasMovingCount_; ++k) {
    const int part = wasMoving_[k];
    if (std::find(moving.begin(), moving.end(), part) == moving.end())
      logMove(part, poses[static_cast<std::size_t>(part)]);
  }
  snap_.movingCount = 0;
  for (const int part : moving) {
    if (snap_.movingCount == ServoSnapshot::kMaxMoving) break;
    snap_.moving[snap_.movingCount++] = {part, poses[static_cast<std::size_t>(part)]};
  }
  wasMovingCount_ = snap_.movingCount;
  for (int k = 0; k < snap_.movingCount; ++k) wasMoving_[k] = snap_.moving[k].part;
}

}  // namespace hg::servo
