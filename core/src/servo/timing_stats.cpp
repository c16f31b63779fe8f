#include "hapticgrasp/servo/timing_stats.hpp"

#include <algorithm>
#include <cmath>

namespace hg::servo {

void DurationHistogram::add(double seconds) noexcept {
  if (!(seconds >= 0)) seconds = 0;  // NaN too
  int bin = 0;
  if (seconds >= kMin_s) {
    const double position = std::log10(seconds / kMin_s) * kBinsPerDecade;
    bin = position >= kBins - 2 ? kBins - 1 : 1 + static_cast<int>(position);
  }
  ++bins_[static_cast<std::size_t>(bin)];
  ++count_;
  sum_ += seconds;
  max_ = std::max(max_, seconds);
}

double DurationHistogram::quantile(double q) const noexcept {
  if (count_ == 0) return 0;
  q = std::clamp(q, 0.0, 1.0);
  const auto rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_))));
  std::uint64_t seen = 0;
  for (int i = 0; i < kBins; ++i) {
    seen += bins_[static_cast<std::size_t>(i)];
    if (seen >= rank) {
      if (i == 0) return std::min(0.5 * kMin_s, max_);
      if (i == kBins - 1) return max_;
      const double centre = kMin_s * std::pow(10.0, (i - 1 + 0.5) / kBinsPerDecade);
      return std::min(centre, max_);
    }
  }
  return max_;
}

DurationSummary DurationHistogram::summary() const noexcept {
  return {1e6 * quantile(0.5), 1e6 * quantile(0.99), 1e6 * max_, 1e6 * mean()};
}

}  // namespace hg::servo
