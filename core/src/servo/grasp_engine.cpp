#include "hapticgrasp/servo/grasp_engine.hpp"

#include <algorithm>
#include <array>

#include "hapticgrasp/grasp/two_finger_grasp.hpp"

namespace hg::servo {
namespace {

std::unique_ptr<contact::CarriedContact> makeContact(const grasp::ScenePtr& scene,
                                                     const std::optional<contact::CarriedContactConfig>& config,
                                                     int slots) {
  if (!config) return nullptr;
  contact::CarriedContactConfig c = *config;
  c.slots = slots;
  return std::make_unique<contact::CarriedContact>(scene, c);
}

bool holds(grasp::GraspState state) noexcept {
  return state == grasp::GraspState::Grasp || state == grasp::GraspState::Manipulate;
}

}  // namespace

TwoFingerEngine::TwoFingerEngine(grasp::ScenePtr scene, const grasp::GraspParameters& parameters,
                                 const std::optional<contact::CarriedContactConfig>& contact)
    : grasp_(std::make_unique<grasp::TwoFingerGrasp>(scene, parameters)), contact_(makeContact(scene, contact, 1)) {}

TwoFingerEngine::~TwoFingerEngine() = default;

std::size_t TwoFingerEngine::partCount() const noexcept { return grasp_->poses().size(); }
void TwoFingerEngine::reset() noexcept {
  grasp_->reset();
  if (contact_) contact_->reset();
  held_ = -1;
}
grasp::GraspState TwoFingerEngine::state() const noexcept { return grasp_->state(); }
std::span<const grasp::PartPose> TwoFingerEngine::poses() const noexcept { return grasp_->poses(); }
const grasp::Scene& TwoFingerEngine::parts() const noexcept { return grasp_->scene(); }

EngineStep TwoFingerEngine::step(const grasp::HandSample& hand, double dt) noexcept {
  const grasp::GraspOutput g = grasp_->step(hand, dt);
  EngineStep s;
  s.events = g.events;
  s.graspedPart = g.graspedPart;
  s.validSample = g.validSample;
  if (g.validSample) {
    s.command.f_index = g.f_index;
    s.command.f_thumb = g.f_thumb;
    s.command.f_wrist = g.f_wrist;
    s.command.m_wrist = g.m_wrist;
    s.command.f_grasp = g.f_grasp;
    if (contact_) couple(hand, g.events, dt, s);
  }
  held_ = holds(g.state) ? g.graspedPart : -1;
  return s;
}

// The part moves from the grasp on (in GRASP it already follows the hand, held back by the
// springs of eq 23), so it is coupled from the grasp to the release. Its fingertip forces
// are the grasp's (eq 24); the contact reaches the hand where its weight does, the wrist:
// the coupling's force acts at the part's centre where the hand wants it, hence its moment
// about the wrist (as eq 30's weight acts at the centre of gravity).
void TwoFingerEngine::couple(const grasp::HandSample& hand, std::uint32_t events, double dt, EngineStep& s) noexcept {
  contact_->beginTick();
  if ((events & grasp::kRelease) && held_ >= 0) contact_->putDown(held_, grasp_->poses()[held_]);
  const int part = holds(grasp_->state()) ? s.graspedPart : -1;
  if (part < 0) return;
  if (events & grasp::kGrasp) contact_->lift(part, grasp_->poses()[part]);
  const contact::CouplingOutput* c = contact_->carry(part, grasp_->poses()[part], dt);
  s.contact = contact_->report();
  if (!c) return;
  grasp_->placeHeld(c->pose);
  s.command.f_wrist += c->force_N;
  s.command.m_wrist += c->torque_Nm + (c->handCentre - hand.wrist).cross(c->force_N);
}

MultiFingerEngine::MultiFingerEngine(grasp::ScenePtr scene, int fingertips,
                                     const grasp::multi_finger::MultiFingerSceneParams& parameters,
                                     const std::optional<contact::CarriedContactConfig>& contact)
    : scene_(scene, fingertips, parameters), contact_(makeContact(scene, contact, 2)) {}

void MultiFingerEngine::reset() noexcept {
  scene_.reset();
  if (contact_) contact_->reset();
  wasCarriedCount_ = 0;
}

EngineStep MultiFingerEngine::step(const grasp::HandSample& hand, double dt) noexcept {
  std::array<Vec3, grasp::HandSample::kMaxFingertips> tips;
  const int n = scene_.fingers();
  for (int k = 0; k < n; ++k) tips[static_cast<std::size_t>(k)] = hand.fingertip(k);
  const grasp::multi_finger::MultiFingerSceneOutput& o = scene_.step(std::span<const Vec3>(tips.data(), n), dt);
  EngineStep s;
  s.events = o.events;
  s.graspedPart = o.graspedPart;
  s.validSample = o.validSample;
  // Fingertip forces only: the method carries the weight in the fingers (eq 19), so the
  // wrist and a grip joint display nothing of their own.
  for (int k = 0; k < n; ++k) s.command.fingertipForce(k) = o.force[static_cast<std::size_t>(k)];
  if (contact_ && o.validSample) couple(dt, s);
  return s;
}

// A part put down this tick is taken where the contact lets it rest (one more coupling
// step from its last pose), a part lifted starts its coupling where it lay, and each
// carried part's body is corrected to where the contact lets it go. The fingers feel the
// stop next tick, through the shell's spring (eq 19 distributes it), not as a force added
// here: the method's own force balance stays whole.
void MultiFingerEngine::couple(double dt, EngineStep& s) noexcept {
  contact_->beginTick();
  const std::span<const int> carried = scene_.carriedParts();
  const auto isCarried = [&](int part) { return std::find(carried.begin(), carried.end(), part) != carried.end(); };
  for (std::size_t k = 0; k < wasCarriedCount_; ++k) {
    const int part = wasCarried_[k];
    if (isCarried(part)) continue;
    if (const contact::CouplingOutput* c = contact_->carry(part, scene_.poses()[static_cast<std::size_t>(part)], dt))
      scene_.constrain(part, c->pose, dt);
    contact_->putDown(part, scene_.poses()[static_cast<std::size_t>(part)]);
  }
  const auto before = wasCarried_;  // a copy: the list is rewritten below
  const auto beforeEnd = before.begin() + static_cast<std::ptrdiff_t>(wasCarriedCount_);
  wasCarriedCount_ = 0;
  for (const int part : carried) {
    const grasp::PartPose& pose = scene_.poses()[static_cast<std::size_t>(part)];
    if (std::find(before.begin(), beforeEnd, part) == beforeEnd) contact_->lift(part, pose);
    if (const contact::CouplingOutput* c = contact_->carry(part, pose, dt)) scene_.constrain(part, c->pose, dt);
    if (wasCarriedCount_ < wasCarried_.size()) wasCarried_[wasCarriedCount_++] = part;
  }
  s.contact = contact_->report();
}

}  // namespace hg::servo
