#pragma once
// Parameters of the two-finger grasp (Maekawa & Hollerbach, sections 2-3), SI. The paper
// gives K_c, B_c, K_g, B_g (section 5); the rest it leaves open, and each default below
// says why it was chosen.
#include "hapticgrasp/math/types.hpp"

namespace hg::grasp {

// How the rotational spring of eq 23 measures the part's turn since the grasp.
enum class RotationalSpring {
  RotationVector,  // m = -K_oe * rotvec(R R_bar^T), R object->absolute: frame-invariant, no wrap
  PaperRpy,        // m = -K_oe * (xi - xi_bar) as printed (differences wrapped into (-pi, pi])
};

struct GraspParameters {
  // Eq 9, fingertip contact: the paper's values.
  double K_c = 130.0;  // N/m^0.5
  double B_c = 100.0;  // N s/m^1.5
  // Eq 24, grasping force between the fingertips: the paper's values.
  double K_g = 1000.0;  // N/m^0.5
  double B_g = 800.0;   // N s/m^1.5
  // Hysteresis of the grasp (Fig. 4, A-D). 2 mm: several times the fingertip-distance
  // noise and tremor of a hand (0.1-0.5 mm), so holding still never releases; small
  // enough that opening the fingers releases at once, and the A->B step K_g sqrt(d_h)
  // stays at 45 N with the paper's K_g (5 mm would give 71 N).
  double d_h = 2e-3;  // m
  // Eq 23, the springs that hold a grasped part in place. K_ox = 2000 N/m: the paper's
  // 2 kg cylinder lifts after M g / K_ox = 9.8 mm, a clear but short pull. K_oe = 20 N m/rad:
  // a 0.1 rad twist gives 2 N m, about what a wrist feels from a 2 kg part held 0.1 m off
  // its centre, so turning and lifting feel alike.
  double K_ox = 2000.0;  // N/m
  double K_oe = 20.0;    // N m/rad
  RotationalSpring rotationalSpring = RotationalSpring::RotationVector;
  // g^a of eqs 29-30: standard gravity along -z.
  Vec3 gravity = Vec3(0, 0, -9.80665);  // m/s^2

  // Cut-off of the first-order low-pass on d|p|/dt (eq 9) and d|x_i - x_t|/dt (eq 24):
  // finite differences at 1-8 kHz are noisy; hand motion is below 10-20 Hz, so 100 Hz
  // keeps the damping's lag under 2 ms. Infinity (or 0) disables the filter.
  double rateCutoff_Hz = 100.0;
  // Contact tracking (PenetrationModel::track): a fingertip keeps the feature it entered
  // through until another is closer by this much, so the force does not flip on a medial
  // axis (a cylinder's rim bisector). 1 mm: well above tracking noise, below any feature.
  double trackingHysteresis_m = 1e-3;
  // A fingertip in contact detaches only this far outside the surface (force is zero
  // meanwhile): tracing at the surface then does not chatter contact/detach events.
  double detachDistance_m = 1e-4;
  // Margin around each part's box for the first (cheap) test of a free fingertip.
  double boxMargin_m = 1e-3;
  // Degenerate grasp frames (eqs 16-17): fingertips closer than this leave h1 undefined;
  // a wrist whose lever |h1 x (x_i - x_w)| / |x_i - x_w| is below minWristSine lies on the
  // finger line and leaves h2 undefined. The last good frame is kept instead.
  double minFingerDistance_m = 1e-6;
  double minWristSine = 1e-3;

  // Throws std::invalid_argument for a negative or non-finite value.
  void validate() const;
};

}  // namespace hg::grasp
