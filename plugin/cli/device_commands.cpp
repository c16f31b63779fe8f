#include "device_commands.hpp"

#include <malloc.h>

#include <cstdio>
#include <iostream>

#include "hapticgrasp/device/device_discovery.hpp"
#include "hapticgrasp/device/hid_layout.hpp"
#include "hapticgrasp/device/hid_transport.hpp"
#include "hapticgrasp/device/udev_rule.hpp"
#include "hapticgrasp/servo/servo_bench.hpp"
// The servo benchmark counts the allocations the servo thread makes: this executable
// interposes malloc (here, and nowhere else in it).
#include "hapticgrasp/servo/malloc_counter.hpp"

namespace hg::cli {

int listDevices() {
  const device::HidLayoutSet layouts = device::loadHidLayoutDirectory(device::defaultHidLayoutDirectory());
  for (const std::string& error : layouts.errors) std::cerr << "layout skipped: " << error << std::endl;
  device::HidapiTransport transport;
  std::cout << device::formatDiscoveredDevices(device::discoverDevices(transport, layouts.layouts));
  return 0;
}

int printUdevRule() {
  const device::HidLayoutSet layouts = device::loadHidLayoutDirectory(device::defaultHidLayoutDirectory());
  for (const std::string& error : layouts.errors) std::cerr << "layout skipped: " << error << std::endl;
  std::cout << device::udevRule(layouts.layouts);
  return layouts.errors.empty() ? 0 : 1;
}

int benchServo(servo::ServoBenchOptions options, bool json) {
  options.realtime = true;
  options.allocationCounter = &servo::threadAllocations;
  const servo::ServoBenchResult r = servo::runServoBench(options);
  if (json) {
    std::cout << servo::toJson(r) << std::endl;
    return 0;
  }
  std::printf("servo loop: part %s, device %s, back end %s, %s method with %d fingertips\n", r.part.c_str(),
              r.device.c_str(), r.backend.c_str(), r.method.c_str(), r.fingers);
  std::printf("servo loop: target %.0f Hz, achieved %.1f Hz over %.1f s; %s, %s\n", r.target_hz, r.achieved_hz,
              r.seconds, r.scheduler.c_str(), r.memory_lock.c_str());
  std::printf("  period error us  p50 %.2f  p99 %.2f  max %.2f\n", r.period_err.p50_us, r.period_err.p99_us, r.period_err.max_us);
  std::printf("  compute us       p50 %.2f  p99 %.2f  max %.2f   (the loop's own work)\n", r.compute.p50_us,
              r.compute.p99_us, r.compute.max_us);
  std::printf("  device I/O us    p50 %.2f  p99 %.2f  max %.2f   (read + write%s)\n",
              r.deviceIo.p50_us, r.deviceIo.p99_us, r.deviceIo.max_us, r.device == "arm" ? "; the simulated arm's physics" : "");
  std::printf("  overruns %llu, allocations in the loop %ld, grasps %llu, lifts %llu, watchdog trips %llu\n",
              static_cast<unsigned long long>(r.overruns), r.allocations_in_loop,
              static_cast<unsigned long long>(r.grasps), static_cast<unsigned long long>(r.lifts),
              static_cast<unsigned long long>(r.watchdog_trips));
  if (r.contact_polls > 0)
    std::printf("  contact with the floor at %llu of the 10 ms looks, deepest %.1f um\n",
                static_cast<unsigned long long>(r.contact_polls), r.contact_max_penetration_m * 1e6);
  if (r.recording.enabled)
    std::printf("  recorded %s: %llu ticks, %llu messages, %.2f MB, %llu records dropped%s%s\n", r.recording.path.c_str(),
                static_cast<unsigned long long>(r.recording.ticks), static_cast<unsigned long long>(r.recording.messages),
                r.recording.bytes / 1e6, static_cast<unsigned long long>(r.recording.droppedRecords),
                r.recording.error.empty() ? "" : "; ", r.recording.error.c_str());
  return r.recording.error.empty() ? 0 : 1;
}

int benchScene(servo::SceneBenchOptions options, bool json) {
  options.realtime = true;
  options.allocationCounter = &servo::threadAllocations;
  const servo::SceneBenchResult r = servo::runSceneBench(options);
  if (json) {
    std::cout << servo::toJson(r) << std::endl;
    return 0;
  }
  std::printf("scene: %zu parts, %zu distinct models (%zu failed), loaded as %s%s; file read in %.3f s\n", r.parts,
              r.uniqueModels, r.failedModels, r.load.c_str(),
              r.load == "loader" ? (" (" + std::to_string(r.loaderProcesses) + " processes)").c_str() : "", r.read_s);
  std::printf("  servo running %.3f s after Start; %s exact and touched at %.3f s; every model built at %.3f s\n",
              r.start_s, r.target.c_str(), r.first_touch_s, r.all_built_s);
  std::printf("  compute us  p50 %.2f  p99 %.2f  max %.2f; period error p99 %.2f us; %.1f Hz; %s\n", r.compute.p50_us,
              r.compute.p99_us, r.compute.max_us, r.periodError.p99_us, r.achieved_hz, r.scheduler.c_str());
  std::printf("  memory %.1f MB, allocations in the loop %ld\n", r.memory_bytes / 1e6, r.allocations_in_loop);
  return 0;
}

}  // namespace hg::cli

namespace hg::cli {

int soak(servo::SoakOptions options, bool json) {
  // One malloc arena for the whole soak. glibc gives each new thread an arena of its own and
  // keeps the pages a finished thread freed there; every segment starts its servo, recorder
  // and build threads anew, so over an hour resident memory crept up by 11.6 MB while the
  // bytes in use stayed flat (fragmentation, not a leak). The servo thread allocates nothing,
  // so sharing one arena costs it nothing; set before the first thread exists.
  mallopt(M_ARENA_MAX, 1);
  options.realtime = true;
  options.allocationCounter = &servo::threadAllocations;
  const servo::SoakResult r = servo::runSoak(options);
  if (json) {
    std::cout << servo::toJson(r) << std::endl;
    return r.passed() ? 0 : 1;
  }
  std::printf("soak: %.1f min, %d segments, %llu ticks (min %.1f Hz), %s\n", r.seconds / 60, r.segments,
              static_cast<unsigned long long>(r.ticks), r.achieved_hz_min, r.scheduler.c_str());
  std::printf("  faults handled %llu of %llu:", static_cast<unsigned long long>(r.faults_handled),
              static_cast<unsigned long long>(r.faults_injected));
  for (int k = 0; k < device::kFaultKinds; ++k)
    std::printf(" %s %llu/%llu", device::toString(static_cast<device::FaultKind>(k)),
                static_cast<unsigned long long>(r.handled[k]), static_cast<unsigned long long>(r.injected[k]));
  std::printf("\n  NaN outputs %llu, unbounded %llu, servo allocations %ld, RSS growth %lld B (RSS %.1f MB), "
              "heap in use growth %lld B\n",
              static_cast<unsigned long long>(r.nan_outputs), static_cast<unsigned long long>(r.unbounded_outputs),
              r.allocations, static_cast<long long>(r.rss_growth_bytes), r.rss_bytes / 1e6,
              static_cast<long long>(r.heap_growth_bytes));
  std::printf("  period error max %.0f us (stalls included), %.0f us outside stalls; longest tick's own work %.0f us; "
              "grasps %llu, lifts %llu, watchdog trips %llu, clears %llu\n",
              r.max_period_err_us, r.max_period_err_unstalled_us, r.max_compute_us, static_cast<unsigned long long>(r.grasps),
              static_cast<unsigned long long>(r.lifts), static_cast<unsigned long long>(r.watchdog_trips),
              static_cast<unsigned long long>(r.watchdog_clears));
  for (const std::string& line : r.unhandled) std::printf("  not handled: %s\n", line.c_str());
  std::printf("  contact with a floor in %d segments: pressed on it at %llu of the 10 ms looks, deepest %.1f um\n",
              r.contact_segments, static_cast<unsigned long long>(r.contact_polls), r.contact_max_penetration_m * 1e6);
  std::printf("  recorded %.1f MB, %llu records dropped%s%s\n%s\n", r.recorded_bytes / 1e6,
              static_cast<unsigned long long>(r.dropped_records), r.recording_error.empty() ? "" : "; error: ",
              r.recording_error.c_str(), r.passed() ? "soak: passed" : "soak: FAILED");
  return r.passed() ? 0 : 1;
}

long threadAllocations() { return servo::threadAllocations(); }

}  // namespace hg::cli
