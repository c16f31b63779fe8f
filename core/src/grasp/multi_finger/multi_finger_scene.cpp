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
  poses_.resize(scene_->size());
  swaps_ = ModelSwaps(*scene_);
  std::vector<geometry::Aabb> boxes(scene_->size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    poses_[i] = scene_->part(i).initialPose;
    boxes[i] = worldBox(i);
  }
  boxes_ = BroadPhase(boxes);
  if (scene_->size() > 0) {  // the pool's states, bound to part 0 until needed elsewhere
    const ScenePart& first = scene_->part(0);
    for (Bound& b : pool_) {
      b.method = std::make_unique<MultiFingerGrasp>(first.penetration, first.mass, fingers, params_.grasp);
      b.resting.assign(static_cast<std::size_t>(fingers), GodObject(*first.penetration, restingParams(params_.grasp)));
    }
  }
  reset();
}

geometry::Aabb MultiFingerScene::worldBox(std::size_t part) const noexcept {
  return poses_[part].absoluteBounds(scene_->part(part).bounds).inflated(params_.boxMargin_m);
}

void MultiFingerScene::reset() noexcept {
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    poses_[i] = scene_->part(i).initialPose;
    boxes_.update(i, worldBox(i));
  }
  for (Bound& b : pool_) {
    if (b.part >= 0) leave(b);
    b.part = -1;
    b.carried = false;
  }
  touching_.fill(false);
  carriedCount_ = 0;
  out_ = MultiFingerSceneOutput{};
  out_.fingers = fingers_;
  out_.part.fill(-1);
  out_.force.fill(Vec3::Zero());
  out_.poses = poses_;
}

bool MultiFingerScene::carried(int part) const noexcept {
  for (const Bound& b : pool_)
    if (b.part == part && b.carried) return true;
  return false;
}

const MultiFingerSceneOutput& MultiFingerScene::step(std::span<const Vec3> tips, double dt) noexcept {
  out_.events = 0;
  out_.force.fill(Vec3::Zero());
  out_.part.fill(-1);
  out_.queried = 0;
  out_.unbound = 0;
  bool finite = static_cast<int>(tips.size()) == fingers_ && std::isfinite(dt) && dt >= 0;
  for (const Vec3& p : tips) finite = finite && p.allFinite();
  out_.validSample = finite;
  if (!finite) return out_;

  refitPublished();
  std::array<int, kPool> parts;
  const int n = nearParts(tips, parts);
  for (Bound& b : pool_) {  // parts no fingertip is near any more: free their state
    if (b.part < 0 || b.carried || std::find(parts.begin(), parts.begin() + n, b.part) != parts.begin() + n) continue;
    leave(b);
    b.part = -1;
  }
  for (int k = 0; k < n; ++k) {  // in part order, as a scan of every part would go
    Bound* b = boundTo(parts[static_cast<std::size_t>(k)]);
    if (!b) b = bind(parts[static_cast<std::size_t>(k)]);
    if (!b) {
      ++out_.unbound;
      continue;
    }
    if (b->carried) {
      stepCarried(*b, tips, dt);
    } else {
      if (b->models != &scene_->part(static_cast<std::size_t>(b->part))) rebind(*b, b->part);  // newer models
      stepResting(*b, tips);
    }
  }
  std::uint32_t events = out_.events;
  settleState(events);
  out_.events = events;
  return out_;
}

void MultiFingerScene::refitPublished() noexcept {
  swaps_.follow(*scene_, [this](int part) {
    const auto i = static_cast<std::size_t>(part);
    if (carried(part)) return;  // a carried part's box: when put down
    const geometry::Aabb box = worldBox(i);  // a box that shrank only costs a query now and then
    if (!geometry::contains(boxes_.box(i), box)) boxes_.update(i, box);
  });
}

int MultiFingerScene::nearParts(std::span<const Vec3> tips, std::array<int, kPool>& parts) noexcept {
  int n = 0;
  const auto add = [&](int part) {
    if (std::find(parts.begin(), parts.begin() + n, part) != parts.begin() + n) return;
    if (n < kPool) parts[static_cast<std::size_t>(n++)] = part;
    else ++out_.unbound;
  };
  for (const Bound& b : pool_)
    if (b.part >= 0 && b.carried) add(b.part);
  int hits[kPool];
  for (const Vec3& x : tips) {
    const std::size_t found = boxes_.query(x, hits);
    for (std::size_t h = 0; h < std::min<std::size_t>(found, kPool); ++h) add(hits[h]);
    if (found > kPool) out_.unbound += static_cast<int>(found - kPool);  // beyond the buffer
  }
  std::sort(parts.begin(), parts.begin() + n);
  return n;
}

MultiFingerScene::Bound* MultiFingerScene::boundTo(int part) noexcept {
  for (Bound& b : pool_)
    if (b.part == part) return &b;
  return nullptr;
}

MultiFingerScene::Bound* MultiFingerScene::bind(int part) noexcept {
  for (Bound& b : pool_) {
    if (b.part >= 0) continue;
    rebind(b, part);
    return &b;
  }
  return nullptr;
}

void MultiFingerScene::rebind(Bound& b, int part) noexcept {
  const ScenePart& models = scene_->part(static_cast<std::size_t>(part));
  b.part = part;
  b.models = &models;
  b.method->rebind(models.penetration, models.mass);
  for (GodObject& g : b.resting) g = GodObject(*models.penetration, restingParams(params_.grasp));
  b.weight_N = models.mass.mass_kg * params_.grasp.gravity.norm();
  b.carried = false;
  b.contacts = 0;
}

void MultiFingerScene::stepResting(Bound& b, std::span<const Vec3> tips) noexcept {
  const PartPose& pose = poses_[static_cast<std::size_t>(b.part)];
  ++out_.queried;
  int contacts = 0;
  double pressing = 0;            // Σ |f_n,i|
  Vec3 net = Vec3::Zero();        // Σ f_n,i n_i, part frame
  for (int i = 0; i < fingers_; ++i) {
    const GodObjectContact& c = b.resting[static_cast<std::size_t>(i)].update(pose.toObject(tips[i]));
    if (!c.inContact) continue;
    ++contacts;
    out_.force[i] += pose.vectorToAbsolute(c.force);
    if (out_.part[i] < 0) out_.part[i] = b.part;
    pressing += c.normalForce;
    net += c.normalForce * c.normal;
  }
  b.contacts = contacts;
  const double squeeze = pressing - net.norm();
  if (contacts >= 2 && squeeze > 0 && params_.grasp.friction * squeeze >= b.weight_N) {
    // The fingers can carry it: from the next tick it is the paper's free body, starting
    // at rest where it lies.
    b.carried = true;
    b.method->reset(pose);
    out_.events |= kLift;
  }
}

void MultiFingerScene::stepCarried(Bound& b, std::span<const Vec3> tips, double dt) noexcept {
  ++out_.queried;
  const MultiFingerOutput& o = dt > 0 ? b.method->step(tips, Vec3::Zero(), Vec3::Zero(), dt) : b.method->output();
  for (int i = 0; i < fingers_; ++i) {
    const FingerOutput& f = o.fingers[static_cast<std::size_t>(i)];
    if (!f.contact) continue;
    out_.force[i] += f.force;
    if (out_.part[i] < 0) out_.part[i] = b.part;
  }
  b.contacts = o.contacts;
  const auto part = static_cast<std::size_t>(b.part);
  poses_[part] = o.body;
  if (o.contacts < 2) {  // put down: it rests where the fingers left it
    b.carried = false;
    leave(b);
    boxes_.update(part, worldBox(part));
    out_.events |= kRelease;
  }
}

void MultiFingerScene::constrain(int part, const PartPose& pose, double dt) noexcept {
  if (part < 0 || static_cast<std::size_t>(part) >= poses_.size()) return;
  const auto i = static_cast<std::size_t>(part);
  poses_[i] = pose;
  Bound* b = boundTo(part);
  if (b && b->carried) b->method->constrainBody(pose, dt);
  else boxes_.update(i, worldBox(i));
}

void MultiFingerScene::leave(Bound& b) noexcept {
  for (GodObject& g : b.resting) g.reset();
  b.contacts = 0;
}

void MultiFingerScene::settleState(std::uint32_t& events) noexcept {
  const GraspState before = out_.state;
  int carried = -1, squeezed = -1;  // the lowest-numbered of each, as a scan of every part finds
  carriedCount_ = 0;
  for (const Bound& b : pool_) {
    if (b.part < 0) continue;
    if (b.carried) carriedList_[carriedCount_++] = b.part;
    if (b.carried && (carried < 0 || b.part < carried)) carried = b.part;
    if (!b.carried && b.contacts >= 2 && (squeezed < 0 || b.part < squeezed)) squeezed = b.part;
  }
  std::sort(carriedList_.begin(), carriedList_.begin() + static_cast<std::ptrdiff_t>(carriedCount_));
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
