#include "hapticgrasp/servo/soak.hpp"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <stdexcept>

#include "hapticgrasp/servo/servo_bench.hpp"

namespace hg::servo {
namespace {

namespace fs = std::filesystem;

// The sample parts the bench's scripted hand can grip across y through their centre (the
// perforated plate has a hole there: the bench refuses it).
constexpr const char* kParts[] = {"cylinder", "block", "loft"};
constexpr int kPartCount = static_cast<int>(std::size(kParts));
constexpr int kRound = 2 * kPartCount;  // every part with both methods
// Contact goes on and off by pairs of segments: every part with both methods, with and
// without contact, takes two rounds. Memory growth is measured from the end of these, when
// every kind of segment has allocated what it keeps (the first loft shell is built in
// segment 10).
constexpr int kCycle = 2 * kRound;

std::int64_t residentBytes() {
  std::ifstream statm("/proc/self/statm");
  std::int64_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * sysconf(_SC_PAGESIZE);
}

// What the program holds from malloc, every arena summed, mmapped blocks included: grows only
// when something is kept (a leak or a cache), not when the allocator keeps freed pages.
std::int64_t heapInUseBytes() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<std::int64_t>(m.uordblks + m.hblkhd);
}

// The swap the workbench makes when a part's model is rebuilt: the same part answered by
// another back end (mesh, then the default again). Built ahead (a loft's mesh takes seconds),
// published at its time.
grasp::ScenePart swapModel(const grasp::Scene& scene, int swaps) {
  grasp::ScenePart part = scene.part(0);
  if (!part.model) return part;
  const geometry::Backend backend = swaps % 2 == 0 ? geometry::Backend::Mesh : geometry::Backend::Auto;
  part.penetration = grasp::makeScenePart(part.model, geometry::MassSpec::mass(part.mass.mass_kg), part.initialPose,
                                          backend).penetration;
  return part;
}

// "segment 7 (block, multi-finger, contact): nan at 12.345 s for 25.0 ms: <why>"
std::string describe(int segment, const ServoBenchOptions& b, const device::UnhandledFault& u) {
  char head[160];
  std::snprintf(head, sizeof head, "segment %d (%s, %s%s): %s at %.3f s for %.1f ms: ", segment, b.part.c_str(),
                b.method.c_str(), b.contact ? ", contact" : "", device::toString(u.fault.kind), u.fault.start_s,
                1e3 * u.fault.duration_s);
  return head + u.why;
}

void add(SoakResult& r, const ServoBenchResult& b, const device::FaultReport& f) {
  r.ticks += b.ticks;
  if (r.allocations >= 0 && b.allocations_in_loop >= 0) r.allocations += b.allocations_in_loop;
  if (b.allocations_in_loop < 0) r.allocations = -1;
  r.nan_outputs += f.nanOutputs;
  r.unbounded_outputs += f.unboundedOutputs;
  for (int k = 0; k < device::kFaultKinds; ++k) {
    r.injected[k] += f.injected[k];
    r.handled[k] += f.handled[k];
  }
  r.max_period_err_us = std::max(r.max_period_err_us, b.period_err.max_us);
  r.max_period_err_unstalled_us = std::max(r.max_period_err_unstalled_us, f.maxPeriodErrUnstalled_us);
  r.max_compute_us = std::max(r.max_compute_us, b.compute.max_us);
  r.achieved_hz_min = r.segments == 0 ? b.achieved_hz : std::min(r.achieved_hz_min, b.achieved_hz);
  r.grasps += b.grasps;
  r.lifts += b.lifts;
  r.watchdog_trips += b.watchdog_trips;
  r.watchdog_clears += b.watchdog_clears;
  r.contact_polls += b.contact_polls;
  r.contact_max_penetration_m = std::max(r.contact_max_penetration_m, b.contact_max_penetration_m);
  r.recorded_bytes += b.recording.bytes;
  r.dropped_records += b.recording.droppedRecords;
  if (r.recording_error.empty()) r.recording_error = b.recording.error;
  r.scheduler = b.scheduler;
  ++r.segments;
}

}  // namespace

bool SoakResult::passed() const {
  return ticks > 0 && nan_outputs == 0 && unbounded_outputs == 0 && allocations == 0 && faults_handled == faults_injected &&
         rss_growth_bytes < 2 * 1024 * 1024 && recording_error.empty();
}

SoakResult runSoak(const SoakOptions& o) {
  if (!(o.minutes > 0 && o.minutes <= 1440)) throw std::invalid_argument("soak minutes must be in (0, 1440]");
  const double total_s = 60 * o.minutes;
  // Segments of a minute at most, and short runs still meet every part and both methods
  // (segments of 5 s at least).
  const int segments = std::max({1, static_cast<int>(std::ceil(total_s / 60)),
                                 std::min(kRound, static_cast<int>(total_s / 5))});
  const double segment_s = total_s / segments;
  fs::path dir = o.recordDir;
  if (o.record && dir.empty()) {
    const char* tmp = std::getenv("TMPDIR");
    std::string tmpl = std::string(tmp && *tmp ? tmp : "/tmp") + "/hapticgrasp-soak-XXXXXX";
    if (!mkdtemp(tmpl.data())) throw std::runtime_error("soak: cannot make a folder for the recordings");  // 0700
    dir = tmpl;
  }
  std::mt19937_64 random(o.seed);
  SoakResult r;
  r.allocations = o.allocationCounter ? 0 : -1;
  std::int64_t warm = -1, warmHeap = -1;
  int kindCursor = 0;  // the device faults' kinds go round across segments
  for (int s = 0; s < segments; ++s) {
    ServoBenchOptions b;
    b.rate_hz = o.rate_hz;
    b.seconds = segment_s;
    b.realtime = o.realtime;
    b.device = "scripted";
    b.part = kParts[(s / 2) % kPartCount];
    b.method = s % 2 == 0 ? "two-finger" : "multi-finger";
    b.fingers = s % 2 == 0 ? 2 : 3;
    b.allocationCounter = o.allocationCounter;
    b.contact = (s / 2) % 2 == 1;  // segments 2, 3 (block), 6, 7 (cylinder), 10, 11 (loft), ...
    r.contact_segments += b.contact ? 1 : 0;
    if (o.record) b.recordPath = (dir / ("segment-" + std::to_string(s) + ".mcap")).string();
    std::shared_ptr<device::FaultInjectingDevice> faults;
    const std::uint64_t wanderSeed = random();
    std::vector<device::Fault> schedule = device::randomFaults(segment_s, o.faultsPerMinute, random, kindCursor);
    kindCursor += static_cast<int>(schedule.size());
    const double ramp = ServoConfig{}.watchdogRamp_s + 4.0 / o.rate_hz;
    b.wrapDevice = [&](std::shared_ptr<device::Device> inner) {
      faults = std::make_shared<device::FaultInjectingDevice>(std::move(inner), schedule, o.rate_hz, ramp, wanderSeed);
      return faults;
    };
    const double swapAt_s = std::uniform_real_distribution<double>(0.3, 0.8)(random) * segment_s;
    std::optional<grasp::ScenePart> swap;
    bool swapped = false;
    b.poll = [&](const grasp::Scene& scene, double t) {
      if (!swap) swap = swapModel(scene, s);
      if (swapped || t < swapAt_s) return;
      swapped = true;
      scene.publish(0, *swap);
      faults->markExternal(device::FaultKind::ModelSwap);
    };
    const ServoBenchResult segment = runServoBench(b);
    const device::FaultReport report = faults->report();
    for (const device::UnhandledFault& u : report.unhandled)
      if (r.unhandled.size() < SoakResult::kMaxUnhandledListed) r.unhandled.push_back(describe(s, b, u));
    add(r, segment, report);
    if (o.record) fs::remove(b.recordPath);
    // The segment's scene, models, recorder and threads are gone: give their freed pages back,
    // as the workbench does when a session stops, so that resident memory counts what is kept.
    malloc_trim(0);
    if (s + 1 == std::min(kCycle, segments)) {
      warm = residentBytes();
      warmHeap = heapInUseBytes();
    }
  }
  if (o.record && o.recordDir.empty()) fs::remove_all(dir);
  r.seconds = total_s;
  for (int k = 0; k < device::kFaultKinds; ++k) {
    r.faults_injected += r.injected[k];
    r.faults_handled += r.handled[k];
  }
  r.rss_bytes = residentBytes();
  r.rss_growth_bytes = r.rss_bytes - warm;
  r.heap_growth_bytes = heapInUseBytes() - warmHeap;
  return r;
}

std::string toJson(const SoakResult& r, int indent) {
  nlohmann::json faults = nlohmann::json::object();
  for (int k = 0; k < device::kFaultKinds; ++k)
    faults[device::toString(static_cast<device::FaultKind>(k))] = {{"injected", r.injected[k]}, {"handled", r.handled[k]}};
  const nlohmann::json j = {{"seconds", r.seconds},
                            {"segments", r.segments},
                            {"ticks", r.ticks},
                            {"nan_outputs", r.nan_outputs},
                            {"unbounded_outputs", r.unbounded_outputs},
                            {"allocations", r.allocations},
                            {"faults_injected", r.faults_injected},
                            {"faults_handled", r.faults_handled},
                            {"faults", faults},
                            {"unhandled", r.unhandled},
                            {"rss_growth_bytes", r.rss_growth_bytes},
                            {"rss_bytes", r.rss_bytes},
                            {"heap_growth_bytes", r.heap_growth_bytes},
                            {"max_period_err_us", r.max_period_err_us},
                            {"max_period_err_unstalled_us", r.max_period_err_unstalled_us},
                            {"max_compute_us", r.max_compute_us},
                            {"achieved_hz_min", r.achieved_hz_min},
                            {"grasps", r.grasps},
                            {"lifts", r.lifts},
                            {"watchdog_trips", r.watchdog_trips},
                            {"watchdog_clears", r.watchdog_clears},
                            {"contact", {{"segments", r.contact_segments}, {"polls", r.contact_polls},
                                         {"max_penetration_m", r.contact_max_penetration_m}}},
                            {"recording", {{"bytes", r.recorded_bytes}, {"dropped_records", r.dropped_records},
                                           {"error", r.recording_error}}},
                            {"scheduler", r.scheduler},
                            {"passed", r.passed()}};
  return j.dump(indent);
}

}  // namespace hg::servo
