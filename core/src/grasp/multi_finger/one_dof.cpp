#include "hapticgrasp/grasp/multi_finger/one_dof.hpp"

#include <algorithm>
#include <cmath>

#include "hapticgrasp/grasp/resultant_distribution.hpp"

namespace hg::grasp::multi_finger {
namespace {

bool finite(double a, double b, double c, double d) {
  return std::isfinite(a) && std::isfinite(b) && std::isfinite(c) && std::isfinite(d);
}
double positive(double value, double fallback) { return value > 0 && std::isfinite(value) ? value : fallback; }
double dampingOf(double k, double m, double zeta) { return 2.0 * std::max(0.0, zeta) * std::sqrt(k * m); }
// The output of a part at rest before any finger touched it (both models start so).
OneDofOutput restingOutput(double x, double v) {
  OneDofOutput out;
  out.partPosition = out.shellPosition = x;
  out.partVelocity = v;
  return out;
}

}  // namespace

void ConventionalOneDof::reset(double partPosition, double partVelocity) noexcept {
  x_ = partPosition;
  v_ = partVelocity;
  haveLast_ = false;
  out_ = restingOutput(x_, v_);
}

const OneDofOutput& ConventionalOneDof::step(double thumb, double index, double fe, double dt) noexcept {
  if (!finite(thumb, index, fe, dt) || !(dt > 0)) return out_;
  const double m = positive(p_.mass, 1.0), k = positive(p_.kGrasp, 1.0), l = std::max(0.0, p_.length);
  const double c = dampingOf(k, m, p_.dampingRatio);
  const double vThumb = haveLast_ ? (thumb - lastThumb_) / dt : 0.0;
  const double vIndex = haveLast_ ? (index - lastIndex_) / dt : 0.0;
  lastThumb_ = thumb;
  lastIndex_ = index;
  haveLast_ = true;

  // Eqs 5/6 with the contacts engaged at the start of the tick: per contact j the force on
  // the part is k (b_j − x') + c (v_j − v'), b_thumb = thumb + l/2, b_index = index − l/2.
  const double bThumb = thumb + 0.5 * l, bIndex = index - 0.5 * l;
  const bool thumbOn = bThumb > x_, indexOn = bIndex < x_;
  double sum = fe;
  int n = 0;
  if (thumbOn) { sum += k * (bThumb - x_) + c * vThumb; ++n; }
  if (indexOn) { sum += k * (bIndex - x_) + c * vIndex; ++n; }
  // Eq 4, backward Euler: m v' = m v + dt (sum − n k dt v' − n c v').
  v_ = (m * v_ + dt * sum) / (m + n * dt * (dt * k + c));
  x_ += dt * v_;

  // Forces at the new state; a contact only pushes.
  const double onThumbSide = bThumb > x_ ? std::max(0.0, k * (bThumb - x_) + c * (vThumb - v_)) : 0.0;
  const double onIndexSide = bIndex < x_ ? std::max(0.0, k * (x_ - bIndex) + c * (v_ - vIndex)) : 0.0;
  out_.thumbForce = -onThumbSide;
  out_.indexForce = onIndexSide;
  out_.resultant = onThumbSide - onIndexSide;  // eq 3, on the part
  out_.graspForce = std::min(onThumbSide, onIndexSide);  // eq 2
  out_.distance = index - thumb;
  out_.partPosition = out_.shellPosition = x_;
  out_.partVelocity = v_;
  out_.grasped = onThumbSide > 0 && onIndexSide > 0;
  return out_;
}

void ProposedOneDof::reset(double partPosition, double partVelocity) noexcept {
  x_ = partPosition;
  v_ = partVelocity;
  haveLast_ = false;
  out_ = restingOutput(x_, v_);
}

const OneDofOutput& ProposedOneDof::step(double thumb, double index, double fe, double dt) noexcept {
  if (!finite(thumb, index, fe, dt) || !(dt > 0)) return out_;
  const double m = positive(p_.mass, 1.0), kg = positive(p_.kGrasp, 1.0), kd = positive(p_.kDynamics, 1.0);
  const double l = std::max(0.0, p_.length);
  const double c = dampingOf(kd, m, p_.dampingRatio);

  // Section 4.1: the mass-less shell balanced by the two grasping springs. Both fingers in
  // it: the balance is the midpoint and each spring is compressed by p = (l − gap)/2. Gap
  // wider than l: every position between the fingers balances; the shell stays on the
  // part unless a finger pushes it.
  const double gap = index - thumb;
  double shell, p;
  bool thumbOn, indexOn;
  if (gap < l) {
    shell = 0.5 * (thumb + index);
    p = 0.5 * (l - gap);
    thumbOn = indexOn = true;
  } else {
    shell = std::clamp(x_, thumb + 0.5 * l, index - 0.5 * l);
    p = 0;
    thumbOn = shell <= thumb + 0.5 * l;
    indexOn = shell >= index - 0.5 * l;
  }
  const bool engaged = thumbOn || indexOn;
  if (!engaged || !haveLast_) lastShell_ = shell;  // no damper kick when a touch begins
  const double shellVelocity = (shell - lastShell_) / dt;
  lastShell_ = shell;
  haveLast_ = true;

  // Section 4.2: the spring-damper between the shell and the mass (backward Euler). The
  // part: m ẍ = k_d (s − x) + c (ṡ − ẋ) + f_e.
  if (engaged) {
    v_ = (m * v_ + dt * (kd * (shell - x_) + c * shellVelocity + fe)) / (m + dt * (dt * kd + c));
  } else {
    v_ += dt * fe / m;
  }
  x_ += dt * v_;

  // Section 4.3: the fingers must give the part m ẍ − f_e, which is the spring-damper's
  // force; eqs 10/11 give it to the finger whose grasping force it increases. In
  // distributeOnLine's convention finger 1 is the index (+x side, d_1 = −p), finger 2 the
  // thumb (d_2 = +p), and its "k_d d_d + f_e" is the force on the part: the damper's share
  // goes in the f_e slot.
  double thumbForce = 0, indexForce = 0, resultant = 0;
  if (engaged) {
    const LineDistribution line = distributeOnLine(kg, -p, p, kd, shell - x_, c * (shellVelocity - v_));
    indexForce = line.f1;
    thumbForce = line.f2;
    // A finger off the shell cannot be given a share (it would pull).
    if (!indexOn) indexForce = 0;
    if (!thumbOn) thumbForce = 0;
    indexForce = std::max(0.0, indexForce);
    thumbForce = std::min(0.0, thumbForce);
    resultant = -(thumbForce + indexForce);
  }
  out_.thumbForce = thumbForce;
  out_.indexForce = indexForce;
  out_.resultant = resultant;
  out_.graspForce = std::min(-thumbForce, indexForce);
  out_.distance = gap;
  out_.partPosition = x_;
  out_.partVelocity = v_;
  out_.shellPosition = shell;
  out_.grasped = thumbOn && indexOn && p > 0;
  return out_;
}

}  // namespace hg::grasp::multi_finger
