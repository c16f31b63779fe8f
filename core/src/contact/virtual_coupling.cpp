#include "hapticgrasp/contact/virtual_coupling.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hg::contact {
namespace {

// The rotation vector of R (angle times unit axis).
Vec3 rotationVector(const Mat3& r) noexcept {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

Mat3 rotationOf(const Vec3& v) noexcept {
  const double angle = v.norm();
  return angle < 1e-15 ? Mat3::Identity() : Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

// Scales v down to length `limit` at most; says whether it did.
bool clampNorm(Vec3& v, double limit) noexcept {
  const double n = v.norm();
  if (n <= limit) return false;
  v *= limit / n;
  return true;
}

}  // namespace

VirtualCoupling::VirtualCoupling(ContactModelPtr held, const CouplingParameters& parameters,
                                 const ContactQueryConfig& query)
    : held_(held),
      parameters_(parameters),
      query_(held, query),
      solver_(query.maxContacts, query_.keyCount()),
      near_(query.maxContacts),
      rows_(query.maxContacts) {
  if (!(parameters.stiffness.translational_N_m > 0) || !(parameters.stiffness.rotational_Nm_rad > 0) ||
      !(parameters.margin_m > 0) || parameters.maxSubsteps < 1 || parameters.solverIterations < 1)
    throw std::invalid_argument("virtual coupling: stiffness, margin, sub-steps and iterations must be positive");
}

void VirtualCoupling::reset(const grasp::PartPose& pose) noexcept {
  pose_ = pose;
  havePrevious_ = false;
  query_.reset();
  port_.reset();
  rotationalPort_.reset();
  handTurn_ = Vec3::Zero();
  out_ = {};
  out_.pose = pose;
  if (held_) out_.handCentre = pose.pointToAbsolute(held_->centre());
}

bool VirtualCoupling::rebind(ContactModelPtr held, const grasp::PartPose& pose) noexcept {
  if (!query_.rebind(held)) return false;
  held_ = std::move(held);
  reset(pose);
  return true;
}

// One sub-step: towards the hand by at most the margin, as far as the contacts allow.
// Returns whether the part reached the hand's pose (no further sub-step needed).
bool VirtualCoupling::substep(const grasp::PartPose& hand, const ContactScene& scene, int held) noexcept {
  const Vec3& centre = held_->centre();
  const Vec3 c = pose_.pointToAbsolute(centre);
  Vec6 target;
  target << hand.pointToAbsolute(centre) - c, rotationVector(hand.rotation * pose_.rotation.transpose());
  const double reach = held_->radius();
  const double move = target.head<3>().norm() + target.tail<3>().norm() * reach;
  const double scale = move > parameters_.margin_m ? parameters_.margin_m / move : 1.0;

  const std::span<const Contact> contacts = query_.run(pose_, scene, held, parameters_.margin_m);
  out_.queried += query_.stats().queried;
  double deepest = 0;
  for (const Contact& k : contacts) deepest = std::max(deepest, -k.gap);
  out_.penetration_m = std::max(out_.penetration_m, deepest);
  // Only the contacts this sub-step can close are rows: a point farther than the part is
  // allowed to move (twice what it is asked to, plus the push-out) cannot be reached. At a
  // hand's usual speeds that is tens of micrometres, not the whole margin. Of those, the
  // ones that decide a rigid motion (contact_reduction.hpp).
  const double allowed = std::min(parameters_.margin_m, 2 * scale * move + deepest + parameters_.rowSlack_m);
  std::size_t near = 0;
  for (const Contact& k : contacts)
    if (k.gap < allowed) near_[near++] = k;
  std::size_t n = reduction_.reduce(std::span<const Contact>(near_.data(), near), rows_);
  if (n > static_cast<std::size_t>(parameters_.maxRows)) {  // the closest ones
    std::nth_element(rows_.begin(), rows_.begin() + parameters_.maxRows, rows_.begin() + n,
                     [](const Contact& a, const Contact& b) { return a.gap < b.gap; });
    n = parameters_.maxRows;
  }
  const ConstraintSolution& s =
      solver_.solve(scale * target, std::span<const Contact>(rows_.data(), n), c, parameters_.stiffness,
                    parameters_.friction, parameters_.solverIterations);
  Vec6 dq = s.displacement;
  // The contacts may push a part out by more than it was asked to move: still within what
  // the rows cover.
  const double moved = dq.head<3>().norm() + dq.tail<3>().norm() * reach;
  if (moved > allowed) dq *= allowed / moved;
  // Renormalised through a quaternion: thousands of small turns a second must not skew it.
  pose_.rotation = Quat(rotationOf(dq.tail<3>()) * pose_.rotation).normalized().toRotationMatrix();
  pose_.position = (c + dq.head<3>()) - pose_.rotation * centre;
  out_.contacts = static_cast<int>(n);
  out_.active = s.active;
  out_.contactForce_N = s.force_N;
  out_.clearance = query_.clearance();
  ++out_.substeps;
  return scale == 1.0;
}

// The coupling's wrench on the hand: spring to the part's constrained pose, damper on
// their relative velocity, passivity-controlled, saturated at the device's limits.
void VirtualCoupling::wrench(const grasp::PartPose& hand, double dt) noexcept {
  const Vec3& centre = held_->centre();
  const Vec3 cPart = pose_.pointToAbsolute(centre), cHand = hand.pointToAbsolute(centre);
  Vec3 force = parameters_.stiffness.translational_N_m * (cPart - cHand);
  // The part is massless: standing in contact, the contacts balance the spring's pull on it
  // exactly, so their force is the spring's (the solver's own is that of the last
  // sub-step's share of the motion only).
  if (out_.active > 0) out_.contactForce_N = force;
  Vec3 torque = parameters_.stiffness.rotational_Nm_rad * rotationVector(pose_.rotation * hand.rotation.transpose());
  if (havePrevious_ && dt > 0) {
    const Vec3 vPart = (cPart - previousPose_.pointToAbsolute(centre)) / dt;
    const Vec3 vHand = (cHand - previousHand_.pointToAbsolute(centre)) / dt;
    const Vec3 wPart = rotationVector(pose_.rotation * previousPose_.rotation.transpose()) / dt;
    const Vec3 wHand = rotationVector(hand.rotation * previousHand_.rotation.transpose()) / dt;
    force += parameters_.damping_Ns_m * (vPart - vHand);
    torque += parameters_.rotationalDamping_Nms_rad * (wPart - wHand);
    handTurn_ += wHand * dt;
  }
  Vec3 passive = force, passiveTorque = torque;
  if (dt > 0) {
    out_.passivityDamping_Ns_m =
        port_.update(cHand, dt, force, parameters_.passivityController, parameters_.maxPassivityDamping_Ns_m, passive);
    out_.rotationalPassivityDamping_Nms_rad =
        rotationalPort_.update(handTurn_, dt, torque, parameters_.passivityController,
                               parameters_.maxRotationalPassivityDamping_Nms_rad, passiveTorque);
  }
  out_.passivityEnergy_J = port_.energy();
  out_.rotationalPassivityEnergy_J = rotationalPort_.energy();
  out_.saturated = clampNorm(passive, parameters_.maxForce_N);
  out_.saturated = clampNorm(passiveTorque, parameters_.maxTorque_Nm) || out_.saturated;
  out_.force_N = passive;
  out_.torque_Nm = passiveTorque;
  out_.handCentre = cHand;
  previousPose_ = pose_;
  previousHand_ = hand;
  havePrevious_ = true;
}

const CouplingOutput& VirtualCoupling::step(const grasp::PartPose& hand, double dt, const ContactScene& scene,
                                            int held) noexcept {
  out_.queried = 0;
  out_.substeps = 0;
  out_.penetration_m = 0;
  out_.lagging = false;
  if (!held_ || !hand.position.allFinite() || !hand.rotation.allFinite()) return out_;  // keep the last answer
  bool reached = false;
  for (int k = 0; k < parameters_.maxSubsteps && !reached; ++k) reached = substep(hand, scene, held);
  out_.lagging = !reached;
  out_.pose = pose_;
  wrench(hand, dt);
  return out_;
}

const CouplingOutput& VirtualCoupling::observe(const grasp::PartPose& hand, const ContactScene& scene,
                                               int held) noexcept {
  if (!held_ || !hand.position.allFinite() || !hand.rotation.allFinite()) return out_;
  const std::span<const Contact> contacts = query_.run(hand, scene, held, parameters_.margin_m);
  double deepest = 0;
  for (const Contact& k : contacts) deepest = std::max(deepest, -k.gap);
  pose_ = hand;
  out_ = {};
  out_.pose = hand;
  out_.handCentre = hand.pointToAbsolute(held_->centre());
  out_.contacts = static_cast<int>(contacts.size());
  out_.queried = query_.stats().queried;
  out_.penetration_m = deepest;
  out_.clearance = query_.clearance();
  return out_;
}

}  // namespace hg::contact
