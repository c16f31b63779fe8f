#include "hapticgrasp/servo/passivity.hpp"

#include <algorithm>

namespace hg::servo {

double PassivityPort::update(const Vec3& x, double dt, const Vec3& f_op, bool controller, double maxDamping,
                             Vec3& out) noexcept {
  out = f_op;
  alpha_ = 0;
  if (!havePosition_ || !(dt > 0) || !x.allFinite()) {
    if (x.allFinite()) {
      x_ = x;
      havePosition_ = true;
    }
    v_.setZero();
    dissipatedPending_ = 0;
    return 0;
  }
  v_ = (x - x_) / dt;
  x_ = x;
  // E(n) = E(n-1) + T f_env(n).v(n) + T alpha(n-1)|v(n-1)|^2, with f_env = -f_op.
  if (f_op.allFinite()) energy_ += dt * (-f_op).dot(v_);
  energy_ += dissipatedPending_;
  dissipatedPending_ = 0;
  const double vv = v_.squaredNorm();
  if (controller && energy_ < 0 && vv > 1e-18 && maxDamping > 0) {
    alpha_ = std::min(-energy_ / (dt * vv), maxDamping);
    out = f_op - alpha_ * v_;               // damping opposes the port's motion
    dissipatedPending_ = dt * alpha_ * vv;  // what it dissipates, seen at the next update
  }
  return alpha_;
}

}  // namespace hg::servo
