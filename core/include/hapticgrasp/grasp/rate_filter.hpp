#pragma once
// d/dt of a sampled signal: a finite difference through a first-order low-pass. Used for
// d|p|/dt in eq 9 and d|x_i - x_t|/dt in eq 24, where raw differences at kHz rates are
// noise times B. The low-pass is discretised exactly for each tick's own dt, so jittery
// ticks are fine, and its gain (1 - exp(-w dt)) / dt <= w bounds the answer to a jump of
// the signal by w times the jump, however small dt gets: nothing divides by ~0.
#include <cmath>
#include <numbers>

namespace hg::grasp {

class RateFilter {
 public:
  // Start over at `value` with rate 0.
  void reset(double value) noexcept {
    last_ = value;
    rate_ = 0;
    pending_ = 0;
  }

  // Feed the signal after `dt` seconds; returns the filtered rate. Ticks too short to
  // difference are accumulated into the next one.
  double update(double value, double dt, double cutoff_Hz) noexcept {
    pending_ += dt > 0 ? dt : 0;
    if (pending_ < kMinDt) return rate_;
    const double raw = (value - last_) / pending_;
    const double gain = cutoff_Hz > 0 && std::isfinite(cutoff_Hz)
                            ? -std::expm1(-2 * std::numbers::pi * cutoff_Hz * pending_)
                            : 1.0;
    rate_ += gain * (raw - rate_);
    last_ = value;
    pending_ = 0;
    return rate_;
  }

  double rate() const noexcept { return rate_; }

 private:
  static constexpr double kMinDt = 1e-9;  // s
  double last_ = 0, rate_ = 0, pending_ = 0;
};

}  // namespace hg::grasp
