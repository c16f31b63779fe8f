#pragma once
// Timing statistics of a servo loop without allocation: fixed, log-spaced histograms of
// durations (10 ns .. 10 s, 24 bins per decade, so a percentile is within ~10% of the
// truth; the maximum is exact).
#include <array>
#include <cstdint>

namespace hg::servo {

// Percentiles of one duration, microseconds.
struct DurationSummary {
  double p50_us = 0;
  double p99_us = 0;
  double max_us = 0;
  double mean_us = 0;
};

struct TimingSummary {
  double target_hz = 0;
  double achieved_hz = 0;      // ticks run / time from the first tick to the last
  std::uint64_t ticks = 0;     // ticks run
  std::uint64_t overruns = 0;  // ticks skipped because a deadline was missed
  std::uint64_t lateTicks = 0; // ticks that woke after their deadline's successor was due
  DurationSummary periodError; // |dt - T|, dt measured between successive wake-ups
  // The loop's own work per tick: commands, grasp, passivity, saturation. The device's
  // read() and write() are not in it: for a real device they are I/O, for the simulated
  // arm they carry its physics; they are timed apart, in deviceIo.
  DurationSummary compute;
  DurationSummary deviceIo;    // device read() + write()
};

class DurationHistogram {
 public:
  static constexpr double kMin_s = 1e-8;
  static constexpr int kBinsPerDecade = 24;
  static constexpr int kDecades = 9;
  static constexpr int kBins = kBinsPerDecade * kDecades + 2;  // + underflow, overflow

  void add(double seconds) noexcept;
  void clear() noexcept { *this = DurationHistogram{}; }
  std::uint64_t count() const noexcept { return count_; }
  // q in [0, 1]; the geometric centre of the bin holding the q-quantile, clamped to max.
  double quantile(double q) const noexcept;
  double max() const noexcept { return max_; }
  double mean() const noexcept { return count_ ? sum_ / static_cast<double>(count_) : 0; }
  DurationSummary summary() const noexcept;

 private:
  std::array<std::uint32_t, kBins> bins_{};
  std::uint64_t count_ = 0;
  double sum_ = 0;
  double max_ = 0;
};

}  // namespace hg::servo
