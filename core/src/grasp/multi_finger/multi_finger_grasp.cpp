#include "hapticgrasp/grasp/multi_finger/multi_finger_grasp.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hapticgrasp/grasp/multi_finger/shape_shell.hpp"
#include "hapticgrasp/math/rpy.hpp"

namespace hg::grasp::multi_finger {
namespace {

std::array<GodObject, kMaxFingers> makeGods(const geometry::PenetrationModel& model, const GodObjectParams& p) {
  return {GodObject(model, p), GodObject(model, p), GodObject(model, p), GodObject(model, p), GodObject(model, p)};
}

// Eq 19 weighing the torque ~not at all: the shares for the force alone.
DistributionParams forceOnlyParams(DistributionParams p) {
  p.gamma1 = 1e-12;
  return p;
}

GodObjectParams godParams(const MultiFingerParams& p) {
  GodObjectParams g;
  g.stiffness = p.stiffness;
  g.friction = p.friction;
  return g;
}

const geometry::PenetrationModel& checked(const std::shared_ptr<const geometry::PenetrationModel>& model) {
  if (!model) throw std::invalid_argument("multi-finger grasp: no penetration model");
  return *model;
}

// Turns the shell rigidly by the rotation vector `turn` (world) about the point `pivot`.
void turnShell(PartPose& shell, const Vec3& pivot, const Vec3& turn) noexcept {
  const Mat3 R = math::fromRotationVector(turn);
  shell.rotation = math::orthonormalized(R * shell.rotation);
  shell.position = pivot + R * (shell.position - pivot);
}

}  // namespace

MultiFingerGrasp::MultiFingerGrasp(std::shared_ptr<const geometry::PenetrationModel> model,
                                   const geometry::MassProperties& mass, int fingers, const MultiFingerParams& params)
    : model_(std::move(model)),
      params_(params),
      count_(fingers),
      gods_(makeGods(checked(model_), godParams(params))),
      body_(mass.mass_kg, mass.centre_m, mass.inertia_kgm2),
      distributor_(params.distribution),
      forceOnly_(forceOnlyParams(params.distribution)) {
  if (fingers < 1 || fingers > kMaxFingers) throw std::invalid_argument("multi-finger grasp: 1 to 5 fingers");
  if (!(mass.mass_kg > 0)) throw std::invalid_argument("multi-finger grasp: the part needs a positive mass");
  radiusOfGyration2_ = std::max(1e-8, mass.inertia_kgm2.trace() / (2 * mass.mass_kg));
  out_.count = count_;
  reset(PartPose{});
}

void MultiFingerGrasp::rebind(std::shared_ptr<const geometry::PenetrationModel> model,
                              const geometry::MassProperties& mass) noexcept {
  model_ = std::move(model);
  gods_ = makeGods(*model_, godParams(params_));
  body_ = RigidBody(mass.mass_kg, mass.centre_m, mass.inertia_kgm2);
  radiusOfGyration2_ = std::max(1e-8, mass.inertia_kgm2.trace() / (2 * mass.mass_kg));
  distributor_.reset();
  forceOnly_.reset();
  reset(PartPose{});
}

void MultiFingerGrasp::reset(const PartPose& pose) noexcept {
  for (GodObject& g : gods_) g.reset();
  body_.reset(pose);
  distributor_.reset();
  forceOnly_.reset();
  shell_ = lastShell_ = pose;
  haveLast_ = false;
  haveTips_ = false;
  shellV_ = shellW_ = Vec3::Zero();
  out_ = MultiFingerOutput{};
  out_.count = count_;
  out_.shell = out_.body = pose;
}

const MultiFingerOutput& MultiFingerGrasp::step(std::span<const Vec3> tips, const Vec3& externalForce,
                                                const Vec3& externalTorque, double dt) noexcept {
  if (static_cast<int>(tips.size()) != count_ || !(dt > 0) || !std::isfinite(dt) || !externalForce.allFinite() ||
      !externalTorque.allFinite())
    return out_;
  for (const Vec3& p : tips)
    if (!p.allFinite()) return out_;
  if (params_.method == Method::Conventional) return stepConventional(tips, externalForce, externalTorque, dt);
  const double k = std::max(0.0, params_.stiffness);

  // 1. The god objects on the shell.
  std::array<Vec3, kMaxFingers> p{}, r{}, n{};
  std::array<int, kMaxFingers> slot{};
  int m = 0;
  for (int i = 0; i < count_; ++i) {
    out_.fingers[i] = FingerOutput{};
    const GodObjectContact& c = gods_[i].update(shell_.toObject(tips[i]));
    if (!c.inContact) continue;
    p[m] = tips[i];
    r[m] = shell_.pointToAbsolute(c.proxy);
    n[m] = shell_.vectorToAbsolute(c.normal);
    slot[m] = i;
    ++m;
  }
  const bool wasHeld = out_.contacts > 0;
  out_.contacts = m;

  // 2. The shell's balance (eqs 15–18); the god objects follow it.
  if (m > 0) {
    const ShellBalance b = balanceShell(std::span<const Vec3>(p.data(), m), std::span<const Vec3>(r.data(), m));
    if (b.valid) {
      shell_.rotation = math::orthonormalized(b.rotation * shell_.rotation);
      shell_.position = b.centre + b.rotation * (shell_.position - b.centre) + b.translation;
      for (int j = 0; j < m; ++j) {
        r[j] = b.centre + b.rotation * (r[j] - b.centre) + b.translation;
        n[j] = b.rotation * n[j];
      }
    }
  }

  // 3./4. The part's mass and inertia, pulled towards the shell while a finger holds it.
  const double mass = body_.mass();
  const double kd = std::max(0.0, params_.dynamicsStiffness);
  const double zeta = std::max(0.0, params_.dampingRatio);
  SpringDamper6 spring;
  const Vec3 gravityForce = mass * params_.gravity;
  if (m > 0) {
    // The shell's velocity for the dampers, low-passed (shellVelocityTau): the mass-less
    // shell can jump in one tick (a finger pushing it against sliding contacts), and a raw
    // jump / dt would kick the damper without bound.
    if (wasHeld && haveLast_) {
      const Vec3 rawV = (shell_.pointToAbsolute(body_.centre()) - lastShell_.pointToAbsolute(body_.centre())) / dt;
      const Vec3 rawW = math::rotationVector(shell_.rotation * lastShell_.rotation.transpose()) / dt;
      const double alpha = dt / (std::max(0.0, params_.shellVelocityTau) + dt);
      shellV_ += alpha * (rawV - shellV_);
      shellW_ += alpha * (rawW - shellW_);
    } else {
      shellV_ = body_.velocity();
      shellW_ = body_.angularVelocity();
    }
    // Balanced pose to balanced pose: step 8's slip turn of the last tick is counted here
    // once, together with this tick's balance. Measured from the pose after the slip turn
    // instead, the filter saw only the balance turning the shell back, every tick the same
    // way: a one-sided shell spin that the damper fed into the part, which spun up without
    // bound (the five-finger runaway test).
    lastShell_ = shell_;
    const Vec3 vs = shellV_, ws = shellW_;
    spring.k = kd;
    spring.c = 2 * zeta * std::sqrt(kd * mass);
    spring.kr = params_.rotationalStiffness > 0 ? params_.rotationalStiffness : kd * radiusOfGyration2_;
    spring.cr = 2 * zeta * std::sqrt(spring.kr * mass * radiusOfGyration2_);
    body_.step(shell_, vs, ws, spring, gravityForce + externalForce, externalTorque, dt);
  } else {
    body_.step(body_.pose(), Vec3::Zero(), Vec3::Zero(), spring, gravityForce + externalForce, externalTorque, dt);
  }
  const Vec3 F = m > 0 ? body_.springForce() : Vec3::Zero();
  const Vec3 N = m > 0 ? body_.springTorque() : Vec3::Zero();
  const Vec3 centre = shell_.pointToAbsolute(body_.centre());

  // 5./6. Grasping forces, and the resultant distributed by eq 19.
  std::array<FingerContact, kMaxFingers> contacts{};
  std::array<Vec3, kMaxFingers> grasp{};
  for (int j = 0; j < m; ++j) {
    grasp[j] = k * (r[j] - p[j]);  // on the finger
    contacts[j].position = r[j];
    contacts[j].normal = -n[j];
    contacts[j].graspForce = grasp[j].norm();
  }
  std::array<double, kMaxFingers> share{};
  if (m > 0) distribute(std::span<const FingerContact>(contacts.data(), m), F, N, centre, share);
  Vec3 unmatchedForce = F, unmatchedTorque = N;
  for (int j = 0; j < m; ++j) {
    unmatchedForce -= share[j] * contacts[j].normal.normalized();
    unmatchedTorque -= (r[j] - centre).cross(share[j] * contacts[j].normal.normalized());
  }

  // Eq 19 gives only normal pushes: what is left of the force along the surfaces (a
  // weight held between two vertical faces) is friction, at most μ times each normal force.
  std::array<Vec3, kMaxFingers> tangential{};
  for (int j = 0; j < m; ++j) {
    const double normalForce = std::max(0.0, grasp[j].dot(n[j])) + share[j];
    const double limit = std::max(0.0, params_.friction) * normalForce;
    Vec3 t = (unmatchedForce - unmatchedForce.dot(n[j]) * n[j]) / static_cast<double>(m - j);
    const double size = t.norm();
    if (size > limit) t *= limit / size;
    tangential[j] = t;  // on the part
    unmatchedForce -= t;
    unmatchedTorque -= (r[j] - centre).cross(t);
  }

  // 7. Torsional friction takes what is left of the torque about the normals.
  bool slipping = false;
  std::array<double, kMaxFingers> torsion{};
  Vec3 slipAxis = Vec3::Zero();
  for (int j = 0; j < m; ++j) {
    const double normalForce = std::max(0.0, grasp[j].dot(n[j])) + share[j];
    const double limit = std::max(0.0, params_.torsionalFriction) * normalForce;
    const double wanted = unmatchedTorque.dot(n[j]) / static_cast<double>(m - j);
    torsion[j] = std::clamp(wanted, -limit, limit);
    unmatchedTorque -= torsion[j] * n[j];
    if (std::abs(wanted) > limit + 1e-12) {
      slipping = true;
      if (slipAxis.isZero()) slipAxis = n[j];
    }
  }
  // 8. Beyond the torsional limit the part turns in the grasp: the shell gives way about
  // the contact normal a, TOWARDS the body, until the spring-damper asks no more than the
  // fingers hold. Turning the shell by −δ a lowers the spring's torque about a by kr δ at
  // once and, through the filtered shell velocity the damper sees next tick, by cr α δ / dt:
  // δ = excess / (kr + cr α / dt). While the body turns away (the slip's direction) the
  // shell also follows its turn this tick, so the spring holds no more than the fingers
  // and the part spins up as under kinetic torsional friction, whatever dt (without it the
  // lag acted as a drag ∝ dt). (Turning by +excess / kr, as before, turned the shell AWAY
  // from the body and ignored the damper: each slip asked for a larger one, and the part
  // spun up — hundreds of rad/s, finger forces of kN.)
  if (slipping) {
    const double alpha = dt / (std::max(0.0, params_.shellVelocityTau) + dt);
    const double give = spring.kr + spring.cr * alpha / dt;
    const double excess = unmatchedTorque.dot(slipAxis);
    const double spin = body_.angularVelocity().dot(slipAxis);
    const double follow = spin * excess < 0 ? spin * dt : 0.0;
    if (give > 0) turnShell(shell_, centre, (follow - excess / give) * slipAxis);
  }

  for (int j = 0; j < m; ++j) {
    FingerOutput& f = out_.fingers[slot[j]];
    f.contact = true;
    f.proxy = r[j];
    f.normal = n[j];
    f.graspForce = grasp[j].norm();
    f.share = share[j];
    f.force = grasp[j] + share[j] * n[j] - tangential[j];
    f.torsion = -torsion[j] * n[j];
  }
  if (m == 0) shell_ = lastShell_ = body_.pose();  // let go: the shell is the part's shape again
  haveLast_ = true;
  out_.shell = shell_;
  out_.body = body_.pose();
  out_.resultantForce = F;
  out_.resultantTorque = N;
  out_.unmatchedForce = unmatchedForce;
  out_.unmatchedTorque = unmatchedTorque;
  out_.slipping = slipping;
  return out_;
}

// Eq 19's shares k_i. Nearly collinear fingers asked for a torque across their line would
// need huge opposed pushes (k_i ~ N / their offset): no finger is given more than the
// whole resultant, cap = |F| + |N| / L, unless the force alone needs more. Clipping each
// k_i to the cap lost the force with the squeeze (two fingers 0.5 mm out of line lost all
// of a shake's 8 N along the grasp), so the torque is given up first: the shares run from
// eq 19 for the force alone (torque weighed ~0) towards the full eq 19 as far as the cap
// allows. Both are ≥ 0 and continuous in the contacts and (F, N), and so is the blend
// (requirements 1 and 3). A larger γ3 cannot do this: it bounds the squeeze only with
// γ3 ≳ 1/8, which also drops ~10 % of every force.
void MultiFingerGrasp::constrainBody(const PartPose& pose, double dt) noexcept {
  body_.correct(pose, dt);
  out_.body = body_.pose();
  if (params_.method == Method::Conventional) out_.shell = out_.body;
}

void MultiFingerGrasp::distribute(std::span<const FingerContact> contacts, const Vec3& F, const Vec3& N,
                                  const Vec3& centre, std::array<double, kMaxFingers>& share) noexcept {
  const int m = static_cast<int>(contacts.size());
  const DistributionResult& full = distributor_.solve(contacts, F, N, centre);
  if (!full.valid) return;
  const double cap = F.norm() + N.norm() / std::max(full.leverArm, 1e-4);
  double largest = 0;
  for (int j = 0; j < m; ++j) largest = std::max(largest, full.k[j]);
  for (int j = 0; j < m; ++j) share[j] = std::min(full.k[j], cap);
  if (largest <= cap) return;
  const DistributionResult& force = forceOnly_.solve(contacts, F, Vec3::Zero(), centre);
  if (!force.valid) return;
  double s = 1;  // how much of the torque the cap lets through
  for (int j = 0; j < m; ++j) {
    if (full.k[j] <= cap) continue;
    s = std::min(s, force.k[j] >= cap ? 0.0 : (cap - force.k[j]) / (full.k[j] - force.k[j]));
  }
  for (int j = 0; j < m; ++j) share[j] = force.k[j] + s * (full.k[j] - force.k[j]);
}

const MultiFingerOutput& MultiFingerGrasp::stepConventional(std::span<const Vec3> tips, const Vec3& externalForce,
                                                            const Vec3& externalTorque, double dt) noexcept {
  const double k = std::max(0.0, params_.stiffness);
  const double mass = body_.mass();
  const double c = 2 * std::max(0.0, params_.contactDampingRatio) * std::sqrt(k * mass);
  const PartPose before = body_.pose();
  const Vec3 centre = body_.centreWorld();

  // The god objects on the part itself; each spring (and damper) acts on the part at r_i.
  std::array<Vec3, kMaxFingers> rho{}, f0{}, applied{}, proxy{};
  std::array<double, kMaxFingers> gain{};
  std::array<int, kMaxFingers> slot{};
  int m = 0;
  for (int i = 0; i < count_; ++i) {
    out_.fingers[i] = FingerOutput{};
    const GodObjectContact& g = gods_[i].update(before.toObject(tips[i]));
    if (!g.inContact) continue;
    const Vec3 r = before.pointToAbsolute(g.proxy);
    Vec3 tipVelocity = Vec3::Zero();
    if (haveTips_) tipVelocity = (tips[i] - lastTips_[i]) / dt;
    rho[m] = r - centre;
    proxy[m] = g.proxy;
    f0[m] = k * (tips[i] - r) + c * tipVelocity;  // on the part, at the start of the tick
    gain[m] = k * dt + c;
    slot[m] = i;
    ++m;
  }
  for (int i = 0; i < count_; ++i) lastTips_[i] = tips[i];
  haveTips_ = true;

  // Eqs 4–6 in 6 DOF: m a = Σ f_i + f_e, I dω = Σ ρ_i × f_i + τ_e.
  body_.stepCoupled(std::span<const Vec3>(rho.data(), m), std::span<const Vec3>(f0.data(), m),
                    std::span<const double>(gain.data(), m), std::span<Vec3>(applied.data(), m),
                    mass * params_.gravity + externalForce, externalTorque, dt);

  const PartPose& now = body_.pose();
  for (int j = 0; j < m; ++j) {
    FingerOutput& f = out_.fingers[slot[j]];
    f.contact = true;
    f.proxy = now.pointToAbsolute(proxy[j]);
    f.normal = now.vectorToAbsolute(gods_[slot[j]].contact().normal);
    f.force = -applied[j];
    f.graspForce = applied[j].norm();
  }
  out_.contacts = m;
  out_.shell = out_.body = now;
  out_.resultantForce = m > 0 ? body_.springForce() : Vec3::Zero();
  out_.resultantTorque = m > 0 ? body_.springTorque() : Vec3::Zero();
  out_.unmatchedForce = out_.unmatchedTorque = Vec3::Zero();
  out_.slipping = false;
  shell_ = lastShell_ = now;
  return out_;
}

}  // namespace hg::grasp::multi_finger
