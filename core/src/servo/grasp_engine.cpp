#include "hapticgrasp/servo/grasp_engine.hpp"

#include <array>

#include "hapticgrasp/grasp/two_finger_grasp.hpp"

namespace hg::servo {

TwoFingerEngine::TwoFingerEngine(grasp::ScenePtr scene, const grasp::GraspParameters& parameters)
    : grasp_(std::make_unique<grasp::TwoFingerGrasp>(std::move(scene), parameters)) {}

TwoFingerEngine::~TwoFingerEngine() = default;

std::size_t TwoFingerEngine::partCount() const noexcept { return grasp_->poses().size(); }
void TwoFingerEngine::reset() noexcept {
  grasp_->reset();
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
  held_ = g.state == grasp::GraspState::Grasp || g.state == grasp::GraspState::Manipulate ? g.graspedPart : -1;
  if (g.validSample) {
    s.command.f_index = g.f_index;
    s.command.f_thumb = g.f_thumb;
    s.command.f_wrist = g.f_wrist;
    s.command.m_wrist = g.m_wrist;
    s.command.f_grasp = g.f_grasp;
  }
  return s;
}

MultiFingerEngine::MultiFingerEngine(grasp::ScenePtr scene, int fingertips,
                                     const grasp::multi_finger::MultiFingerSceneParams& parameters)
    : scene_(std::move(scene), fingertips, parameters) {}

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
  return s;
}

}  // namespace hg::servo
