#include "hapticgrasp/grasp/multi_finger/multi_finger_scene.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hg::grasp::multi_finger {
namespace {

GodObjectParams restingParams(const MultiFingerParams& p) {
  GodObjectParams g;
  g.stiffness = p.stiffness;
  g.friction = p.friction;
  return g;
}

}  // namespace

MultiFingerScene::MultiFingerScene(ScenePtr scene, int fingers, const MultiFingerSceneParams& params)
    : scene_(std::move(scene)), fingers_(fingers), params_(params) {
  if (!scene_) throw std::invalid_argument("multi-finger scene: no scene");
  if (fingers < 1 || fingers > kMaxFingers) throw std::invalid_argument("multi-finger scene: 1 to 5 fingers");
  parts_.reserve(scene_->size());
  for (const ScenePart& sp : scene_->parts()) {
    Part p;
    p.method = std::make_unique<MultiFingerGrasp>(sp.penetration, sp.mass, fingers, params_.grasp);
    for (int i = 0; i < fingers; ++i) p.resting.emplace_back(*sp.penetration, restingParams(params_.grasp));
    p.weight_N = sp.mass.mass_kg * params_.grasp.gravity.norm();
    parts_.push_back(std::move(p));
  }
  poses_.resize(scene_->size());
  reset();
}

void MultiFingerScene::reset() noexcept {
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    poses_[i] = scene_->part(i).initialPose;
    leave(i);
    parts_[i].carried = false;
  }
  touching_.fill(false);
  out_ = MultiFingerSceneOutput{};
  out_.fingers = fingers_;
  out_.part.fill(-1);
  out_.force.fill(Vec3::Zero());
  out_.poses = poses_;
}

const MultiFingerSceneOutput& MultiFingerScene::step(std::span<const Vec3> tips, double dt) noexcept {
  out_.events = 0;
  out_.force.fill(Vec3::Zero());
  out_.part.fill(-1);
  out_.queried = 0;
  bool finite = static_cast<int>(tips.size()) == fingers_ && std::isfinite(dt) && dt >= 0;
  for (const Vec3& p : tips) finite = finite && p.allFinite();
  out_.validSample = finite;
  if (!finite) return out_;

  for (std::size_t i = 0; i < parts_.size(); ++i) {
    if (parts_[i].carried) {
      stepCarried(i, tips, dt);
    } else if (near(i, tips)) {
      stepResting(i, tips);
    } else if (parts_[i].contacts > 0) {
      leave(i);
    }
  }
  std::uint32_t events = out_.events;
  settleState(events);
  out_.events = events;
  return out_;
}

bool MultiFingerScene::near(std::size_t part, std::span<const Vec3> tips) const noexcept {
  const geometry::Aabb box =
      poses_[part].absoluteBounds(scene_->part(part).model->bounds()).inflated(params_.boxMargin_m);
  for (const Vec3& p : tips)
    if (box.contains(p)) return true;
  return false;
}

void MultiFingerScene::stepResting(std::size_t part, std::span<const Vec3> tips) noexcept {
  Part& p = parts_[part];
  const PartPose& pose = poses_[part];
  ++out_.queried;
  int contacts = 0;
  double pressing = 0;            // Σ |f_n,i|
  Vec3 net = Vec3::Zero();        // Σ f_n,i n_i, part frame
  for (int i = 0; i < fingers_; ++i) {
    const GodObjectContact& c = p.resting[static_cast<std::size_t>(i)].update(pose.toObject(tips[i]));
    if (!c.inContact) continue;
    ++contacts;
    out_.force[i] += pose.vectorToAbsolute(c.force);
    if (out_.part[i] < 0) out_.part[i] = static_cast<int>(part);
    pressing += c.normalForce;
    net += c.normalForce * c.normal;
  }
  p.contacts = contacts;
  const double squeeze = pressing - net.norm();
  if (contacts >= 2 && squeeze > 0 && params_.grasp.friction * squeeze >= p.weight_N) {
    // The fingers can carry it: from the next tick it is the paper's free body, starting
    // at rest where it lies.
    p.carried = true;
    p.method->reset(pose);
    out_.events |= kLift;
  }
}

void MultiFingerScene::stepCarried(std::size_t part, std::span<const Vec3> tips, double dt) noexcept {
  Part& p = parts_[part];
  ++out_.queried;
  const MultiFingerOutput& o = dt > 0 ? p.method->step(tips, Vec3::Zero(), Vec3::Zero(), dt) : p.method->output();
  for (int i = 0; i < fingers_; ++i) {
    const FingerOutput& f = o.fingers[static_cast<std::size_t>(i)];
    if (!f.contact) continue;
    out_.force[i] += f.force;
    if (out_.part[i] < 0) out_.part[i] = static_cast<int>(part);
  }
  p.contacts = o.contacts;
  poses_[part] = o.body;
  if (o.contacts < 2) {  // put down: it rests where the fingers left it
    p.carried = false;
    leave(part);
    out_.events |= kRelease;
  }
}

void MultiFingerScene::leave(std::size_t part) noexcept {
  for (GodObject& g : parts_[part].resting) g.reset();
  parts_[part].contacts = 0;
}

void MultiFingerScene::settleState(std::uint32_t& events) noexcept {
  const GraspState before = out_.state;
  int carried = -1, squeezed = -1;
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    if (parts_[i].carried && carried < 0) carried = static_cast<int>(i);
    if (!parts_[i].carried && parts_[i].contacts >= 2 && squeezed < 0) squeezed = static_cast<int>(i);
  }
  std::array<bool, kMaxFingers> touching{};
  bool any = false;
  for (int i = 0; i < fingers_; ++i) any |= touching[i] = out_.part[i] >= 0;
  const std::uint32_t contactBit[2] = {kIndexContact, kThumbContact}, detachBit[2] = {kIndexDetach, kThumbDetach};
  for (int i = 0; i < std::min(fingers_, 2); ++i) {
    if (touching[i] && !touching_[i]) events |= contactBit[i];
    if (!touching[i] && touching_[i]) events |= detachBit[i];
  }
  touching_ = touching;

  if (carried >= 0) {
    out_.state = GraspState::Manipulate;
  } else if (squeezed >= 0) {
    out_.state = GraspState::Grasp;
  } else if (touching[0]) {
    out_.state = GraspState::IndexContact;
  } else {
    out_.state = any ? GraspState::ThumbContact : GraspState::Free;
  }
  out_.graspedPart = carried >= 0 ? carried : squeezed;
  const auto holding = [](GraspState s) { return s == GraspState::Grasp || s == GraspState::Manipulate; };
  if (holding(out_.state) && !holding(before)) events |= kGrasp;
}

}  // namespace hg::grasp::multi_finger
