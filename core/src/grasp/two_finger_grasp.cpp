#include "hapticgrasp/grasp/two_finger_grasp.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hg::grasp {

TwoFingerGrasp::TwoFingerGrasp(ScenePtr scene, const GraspParameters& parameters)
    : scene_(std::move(scene)), k_(parameters) {
  if (!scene_) throw std::invalid_argument("TwoFingerGrasp needs a scene");
  k_.validate();
  poses_.resize(scene_->size());
  swaps_ = ModelSwaps(*scene_);
  std::vector<geometry::Aabb> boxes(scene_->size());
  for (std::size_t i = 0; i < boxes.size(); ++i) boxes[i] = worldBox(static_cast<int>(i), scene_->part(i).initialPose);
  boxes_ = BroadPhase(boxes);
  reset();
}

void TwoFingerGrasp::reset() noexcept {
  for (std::size_t i = 0; i < poses_.size(); ++i) setPose(static_cast<int>(i), scene_->part(i).initialPose);
  state_ = GraspState::Free;
  tips_[kIndex] = tips_[kThumb] = Fingertip{};
  distanceRate_ = RateFilter{};
  haveDistance_ = false;
  pendingDt_ = 0;
  held_ = -1;
  heldModels_ = nullptr;
  frame_ = Mat3::Identity();
}

geometry::Aabb TwoFingerGrasp::worldBox(int part, const PartPose& pose) const noexcept {
  return pose.absoluteBounds(scene_->part(static_cast<std::size_t>(part)).bounds).inflated(k_.boxMargin_m);
}

void TwoFingerGrasp::setPose(int part, const PartPose& pose) noexcept {
  poses_[part] = pose;
  boxes_.update(static_cast<std::size_t>(part), worldBox(part, pose));
}

void TwoFingerGrasp::refitPublished() noexcept {
  swaps_.follow(*scene_, [this](int part) {
    if (part == held_) return;  // the held part's box: at its release
    // A box that shrank only costs a query now and then: refit where it grew.
    const geometry::Aabb box = worldBox(part, poses_[static_cast<std::size_t>(part)]);
    if (!geometry::contains(boxes_.box(static_cast<std::size_t>(part)), box)) boxes_.update(static_cast<std::size_t>(part), box);
  });
}

GraspOutput TwoFingerGrasp::step(const HandSample& hand, double dt) noexcept {
  refitPublished();
  GraspOutput out;
  out.state = state_;
  out.poses = poses_;
  out.graspedPart = held_;
  out.indexPart = held_ >= 0 ? held_ : tips_[kIndex].part;
  out.thumbPart = held_ >= 0 ? held_ : tips_[kThumb].part;
  if (!hand.finite() || !std::isfinite(dt) || dt < 0) {
    // A glitch of the device: no force this tick, nothing remembered from it. Its time
    // still passes, so the next rates difference over the whole gap.
    out.validSample = false;
    if (std::isfinite(dt) && dt > 0) pendingDt_ += dt;
    return out;
  }
  dt += pendingDt_;
  pendingDt_ = 0;
  const double distance = (hand.index - hand.thumb).norm();
  if (!haveDistance_) distanceRate_.reset(distance);
  else distanceRate_.update(distance, dt, k_.rateCutoff_Hz);
  haveDistance_ = true;

  if (state_ == GraspState::Grasp || state_ == GraspState::Manipulate) stepHolding(hand, out);
  // Also on the tick of a release: a fingertip still inside the part it let go of (or
  // that came back onto it) touches it at once.
  if (state_ != GraspState::Grasp && state_ != GraspState::Manipulate) stepTouching(hand, dt, out);
  return out;
}

// FREE, INDEX CONTACT, THUMB CONTACT: the parts stay where they are; each fingertip feels
// a frictionless contact. A fingertip coming into the part the other one touches closes
// the grasp (Fig. 3).
void TwoFingerGrasp::stepTouching(const HandSample& hand, double dt, GraspOutput& out) noexcept {
  const bool wasTouching[2] = {tips_[kIndex].part >= 0, tips_[kThumb].part >= 0};
  out.f_index = touch(kIndex, hand.index, dt, out);
  out.f_thumb = touch(kThumb, hand.thumb, dt, out);
  const int i = tips_[kIndex].part, t = tips_[kThumb].part;
  out.indexPart = i;
  out.thumbPart = t;
  const auto cameIn = [&](Finger f) { return !wasTouching[f] && tips_[f].part >= 0 && tips_[f].armed; };
  if (i >= 0 && i == t && (cameIn(kIndex) || cameIn(kThumb))) {
    beginGrasp(hand, i, out);
    return;
  }
  if (i >= 0 && t >= 0) {
    // Both touch, but two parts, or neither came in from outside (a part put back onto
    // both fingertips by a release): the fingertip that came first names the state.
    if (state_ != GraspState::ThumbContact) state_ = GraspState::IndexContact;
  } else {
    state_ = i >= 0 ? GraspState::IndexContact : t >= 0 ? GraspState::ThumbContact : GraspState::Free;
  }
  out.state = state_;
}

Vec3 TwoFingerGrasp::touch(Finger finger, const Vec3& x, double dt, GraspOutput& out) noexcept {
  Fingertip& tip = tips_[finger];
  const std::uint32_t contactEvent = finger == kIndex ? kIndexContact : kThumbContact;
  const std::uint32_t detachEvent = finger == kIndex ? kIndexDetach : kThumbDetach;
  geometry::Penetration p;
  if (tip.part >= 0) {
    // Only the touched part is asked, through the feature the fingertip entered by.
    p = query(tip, tip.part, x, out);
    if (!(p.depth >= -k_.detachDistance_m)) {
      tip.part = -1;
      tip.armed = true;
      out.events |= detachEvent;
      return Vec3::Zero();
    }
  } else {
    // A free fingertip: the broad phase names the parts whose box holds it; only those
    // are queried (the first kMaxNear of them, should more boxes nest around one point).
    int entered = -1;
    int near[kMaxNear];
    const std::size_t count = std::min<std::size_t>(boxes_.query(x, near), kMaxNear);
    for (std::size_t n = 0; n < count; ++n) {
      const int k = near[n];
      const geometry::Penetration pk = query(tip, k, x, out);
      if (pk.inside && (entered < 0 || pk.depth > p.depth || (pk.depth == p.depth && k < entered))) {
        entered = k;
        p = pk;
      }
    }
    if (entered < 0) {
      tip.armed = true;
      return Vec3::Zero();
    }
    tip.part = entered;
    tip.depthRate.reset(0);  // the penetration grows from zero at the surface
    out.events |= contactEvent;
  }
  // Eq 9 with the part's pose: p^a = R^-1 p^o (eqs 6-7). In the detach band, outside the
  // surface, there is no penetration and no force.
  const double depth = std::max(0.0, p.depth);
  const double rate = tip.depthRate.update(depth, dt, k_.rateCutoff_Hz);
  if (!(depth > 0)) return Vec3::Zero();
  const PartPose& pose = poses_[tip.part];
  return contactForce(pose.vectorToAbsolute(p.vector), pose.vectorToAbsolute(p.normal), rate, k_);
}

geometry::Penetration TwoFingerGrasp::query(Fingertip& tip, int part, const Vec3& x, GraspOutput& out) noexcept {
  const ScenePart& models = scene_->part(static_cast<std::size_t>(part));
  if (tip.queryPart != part || tip.queryModels != &models) {  // another model's warm start means nothing here
    tip.query.reset();
    tip.queryPart = part;
    tip.queryModels = &models;
  }
  ++out.queries;
  // Eqs 2-5: the fingertip in the object frame, then P_o.
  return models.penetration->track(poses_[part].toObject(x), tip.query, k_.trackingHysteresis_m);
}

void TwoFingerGrasp::beginGrasp(const HandSample& hand, int part, GraspOutput& out) noexcept {
  held_ = part;
  heldModels_ = &scene_->part(static_cast<std::size_t>(part));  // its weight stays what the grasp felt first
  frame_ = firstHandFrame(hand, k_);
  memory_ = preserveGrasp(hand, poses_[part], frame_);
  state_ = GraspState::Grasp;
  out.events |= kGrasp;
  hold(hand, out);
}

// GRASP, MANIPULATE: the part follows the hand until the fingertips open past the
// hysteresis (eq 28).
void TwoFingerGrasp::stepHolding(const HandSample& hand, GraspOutput& out) noexcept {
  if ((hand.index - hand.thumb).norm() >= memory_.distance + k_.d_h) {
    release(out);
    return;
  }
  hold(hand, out);
}

void TwoFingerGrasp::hold(const HandSample& hand, GraspOutput& out) noexcept {
  frame_ = handFrame(hand.index, hand.thumb, hand.wrist, frame_, k_);     // eqs 16-18
  const PartPose pose = graspedPose(memory_, frame_, hand.index, hand.thumb);  // eqs 19-22
  poses_[held_] = pose;  // its box is refreshed at the release, the next time it is needed

  const double distance = (hand.index - hand.thumb).norm();
  out.f_grasp = graspingForce(distance, distanceRate_.rate(), memory_.distance, k_);  // eq 24
  out.f_index = out.f_grasp * frame_.col(0);
  out.f_thumb = -out.f_index;

  const ScenePart& part = *heldModels_;
  Wrench wrist;
  if (state_ == GraspState::Grasp) {
    wrist = springWrench(pose, memory_.object, k_);  // eq 23
    if (springsCarryWeight(wrist.force, part.mass.mass_kg, k_)) {  // eq 29, corrected
      state_ = GraspState::Manipulate;
      out.events |= kLift;
    }
  }
  if (state_ == GraspState::Manipulate)
    wrist = gravityWrench(pose, part.mass.centre_m, part.mass.mass_kg, hand.wrist, k_);  // eq 30
  out.f_wrist = wrist.force;
  out.m_wrist = wrist.moment;
  out.state = state_;
  out.graspedPart = held_;
  out.indexPart = out.thumbPart = held_;
}

void TwoFingerGrasp::placeHeld(const PartPose& pose) noexcept {
  if (held_ >= 0 && pose.position.allFinite() && pose.rotation.allFinite()) poses_[held_] = pose;
}

void TwoFingerGrasp::release(GraspOutput& out) noexcept {
  out.events |= kRelease;
  if (state_ == GraspState::Grasp) {
    setPose(held_, memory_.object);  // never lifted: back where it was
    out.events |= kReturn;
  } else {
    setPose(held_, poses_[held_]);   // put down where the hand left it
  }
  state_ = GraspState::Free;
  held_ = -1;
  heldModels_ = nullptr;
  for (Fingertip& tip : tips_) {
    tip.part = -1;
    tip.armed = false;  // a fingertip still inside must leave before it can grasp again
  }
  out.state = state_;
  out.graspedPart = -1;
}

}  // namespace hg::grasp
