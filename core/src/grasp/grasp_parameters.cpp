#include "hapticgrasp/grasp/grasp_parameters.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hg::grasp {
namespace {

void requireNonNegative(double value, const char* name) {
  if (!(value >= 0) || !std::isfinite(value))
    throw std::invalid_argument(std::string("grasp parameter ") + name + " must be finite and >= 0, not " +
                                std::to_string(value));
}

}  // namespace

void GraspParameters::validate() const {
  requireNonNegative(K_c, "K_c");
  requireNonNegative(B_c, "B_c");
  requireNonNegative(K_g, "K_g");
  requireNonNegative(B_g, "B_g");
  requireNonNegative(d_h, "d_h");
  requireNonNegative(K_ox, "K_ox");
  requireNonNegative(K_oe, "K_oe");
  if (!gravity.allFinite()) throw std::invalid_argument("grasp parameter gravity must be finite");
  if (!(rateCutoff_Hz >= 0)) throw std::invalid_argument("grasp parameter rateCutoff_Hz must be >= 0 (or inf)");
  requireNonNegative(trackingHysteresis_m, "trackingHysteresis_m");
  requireNonNegative(detachDistance_m, "detachDistance_m");
  requireNonNegative(boxMargin_m, "boxMargin_m");
  requireNonNegative(minFingerDistance_m, "minFingerDistance_m");
  requireNonNegative(minWristSine, "minWristSine");
  if (minWristSine >= 1) throw std::invalid_argument("grasp parameter minWristSine must be < 1");
}

}  // namespace hg::grasp
