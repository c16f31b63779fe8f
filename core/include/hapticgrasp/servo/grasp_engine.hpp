#pragma once
// The grasp method the servo loop runs, behind one small interface: the first paper's
// two-finger state machine (TwoFingerGrasp) or the resultant-force paper's multi-finger
// method over the scene (MultiFingerScene). The loop gives it each fresh sample and the
// time since the previous one and gets back the forces to display.
//
// Either may keep a carried part out of the others (contact/carried_contact.hpp): the
// part stops at contact and slides; the two-finger hand feels the contact through the
// wrist, on top of the weight of eq 30 (its fingertip forces stay as they are); the
// multi-finger part is a body whose motion the contact corrects, so its fingers feel the
// stop through the shell's spring and eq 19.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "hapticgrasp/contact/carried_contact.hpp"

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/grasp/grasp_parameters.hpp"
#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/multi_finger/multi_finger_scene.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/scene/scene.hpp"

namespace hg::grasp {
class TwoFingerGrasp;
}

namespace hg::servo {

struct EngineStep {
  device::DeviceCommand command;  // what the method asks the device to display
  std::uint32_t events = 0;       // GraspEvent bits
  int graspedPart = -1;
  bool validSample = true;        // false: the sample was unusable; command is zero
  contact::ContactReport contact;  // part-to-part contact this tick (part -1: none)
};

class GraspEngine {
 public:
  virtual ~GraspEngine() = default;
  virtual const char* name() const noexcept = 0;     // "two-finger", "multi-finger"
  virtual int fingertips() const noexcept = 0;       // the device must read this many
  virtual std::size_t partCount() const noexcept = 0;
  // Both run on the servo thread: no allocation, no throw.
  virtual EngineStep step(const grasp::HandSample& hand, double dt) noexcept = 0;
  virtual void reset() noexcept = 0;                 // FREE, every part at its initial pose
  virtual grasp::GraspState state() const noexcept = 0;
  virtual std::span<const grasp::PartPose> poses() const noexcept = 0;
  // The parts whose pose the last step() may have changed (held or carried): the only
  // ones the servo publishes each tick. The others stand where they were put.
  virtual std::span<const int> moving() const noexcept = 0;
  // The parts it grasps (a recording's metadata, the swaps it follows).
  virtual const grasp::Scene& parts() const noexcept = 0;
  // Part-to-part contact, when the engine was made with it.
  virtual const contact::CarriedContact* contact() const noexcept = 0;
};

// The first paper's method: index, thumb and wrist.
class TwoFingerEngine final : public GraspEngine {
 public:
  TwoFingerEngine(grasp::ScenePtr scene, const grasp::GraspParameters& parameters = {},
                  const std::optional<contact::CarriedContactConfig>& contact = std::nullopt);
  ~TwoFingerEngine() override;
  const char* name() const noexcept override { return "two-finger"; }
  int fingertips() const noexcept override { return 2; }
  std::size_t partCount() const noexcept override;
  EngineStep step(const grasp::HandSample& hand, double dt) noexcept override;
  void reset() noexcept override;
  grasp::GraspState state() const noexcept override;
  std::span<const grasp::PartPose> poses() const noexcept override;
  std::span<const int> moving() const noexcept override { return {&held_, held_ >= 0 ? 1u : 0u}; }
  const grasp::Scene& parts() const noexcept override;
  const contact::CarriedContact* contact() const noexcept override { return contact_.get(); }

 private:
  // The held part against the others: where it may go, and the wrench the wrist feels.
  void couple(const grasp::HandSample& hand, std::uint32_t events, double dt, EngineStep& s) noexcept;

  std::unique_ptr<grasp::TwoFingerGrasp> grasp_;
  std::unique_ptr<contact::CarriedContact> contact_;
  int held_ = -1;  // the part in GRASP or MANIPULATE
};

// The resultant-force paper's method with 1–5 fingertips (HandSample::fingertip(k)).
class MultiFingerEngine final : public GraspEngine {
 public:
  // Contact slots: as many carried parts as the pool of the method can bind at once would be
  // wasteful; two (a part in each pair of fingers) is what a hand does.
  MultiFingerEngine(grasp::ScenePtr scene, int fingertips,
                    const grasp::multi_finger::MultiFingerSceneParams& parameters = {},
                    const std::optional<contact::CarriedContactConfig>& contact = std::nullopt);
  const char* name() const noexcept override { return "multi-finger"; }
  int fingertips() const noexcept override { return scene_.fingers(); }
  std::size_t partCount() const noexcept override { return scene_.poses().size(); }
  EngineStep step(const grasp::HandSample& hand, double dt) noexcept override;
  void reset() noexcept override;
  grasp::GraspState state() const noexcept override { return scene_.state(); }
  std::span<const grasp::PartPose> poses() const noexcept override { return scene_.poses(); }
  std::span<const int> moving() const noexcept override { return scene_.carriedParts(); }
  const grasp::Scene& parts() const noexcept override { return scene_.scene(); }
  const grasp::multi_finger::MultiFingerScene& scene() const noexcept { return scene_; }
  const contact::CarriedContact* contact() const noexcept override { return contact_.get(); }

 private:
  // The carried parts against the others: lifted, carried, put down.
  void couple(double dt, EngineStep& s) noexcept;

  grasp::multi_finger::MultiFingerScene scene_;
  std::unique_ptr<contact::CarriedContact> contact_;
  std::array<int, grasp::multi_finger::MultiFingerScene::kPool> wasCarried_{};
  std::size_t wasCarriedCount_ = 0;
};

}  // namespace hg::servo
