#pragma once
// The time-domain passivity observer and controller of Ryu, Kwon & Hannaford ("Time
// domain passivity control of haptic interfaces", 2002), one per port (index fingertip,
// thumb fingertip, wrist).
//
// Sign convention: E counts the energy that flowed INTO the virtual environment from the
// operator. The force in the formula is the force the operator exerts on the environment,
// f_env = -f_op (f_op: the force the device displays on the operator, DeviceCommand), and
// v is the port's velocity (finite difference of its position). So
//   E(n) = E(n-1) + T f_env(n).v(n) + T alpha(n-1) |v(n-1)|^2
// (the last term is what the controller dissipated on the previous tick). E >= 0: the
// environment has been passive so far; E < 0: it has given the operator energy it never
// received (sampling, delay, stiff contacts) -- energy flowing OUT of the virtual
// environment to the operator counts NEGATIVE. The controller then adds a damping
//   alpha(n) = -E(n) / (T |v(n)|^2),  bounded by maxDamping,
// along v for that tick: f_op -= alpha v (a force opposing the port's motion).
//
// Only translational power is observed; the wrist moment's power (m . omega) is not.
#include "hapticgrasp/math/types.hpp"

namespace hg::servo {

class PassivityPort {
 public:
  // A new position sample x, dt seconds after the previous one (dt > 0), and the force
  // the grasp wants to display on the operator (f_op, before this controller). Returns the
  // damping alpha (N s/m, 0 unless the controller is on and E < 0), and sets `out` to the
  // force to display. The first call only records x.
  double update(const Vec3& x, double dt, const Vec3& f_op, bool controller, double maxDamping,
                Vec3& out) noexcept;
  // No new position this tick: the port is treated as still (v = 0), the force as given.
  void reset() noexcept { *this = PassivityPort{}; }

  double energy() const noexcept { return energy_; }  // E(n), J
  double alpha() const noexcept { return alpha_; }    // alpha(n), N s/m
  const Vec3& velocity() const noexcept { return v_; }

 private:
  bool havePosition_ = false;
  Vec3 x_ = Vec3::Zero();
  Vec3 v_ = Vec3::Zero();
  double energy_ = 0;
  double alpha_ = 0;
  double dissipatedPending_ = 0;  // T alpha(n-1) |v(n-1)|^2, added at the next update
};

}  // namespace hg::servo
