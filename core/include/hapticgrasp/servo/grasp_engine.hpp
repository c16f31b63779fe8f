#pragma once
// The grasp method the servo loop runs, behind one small interface: the first paper's
// two-finger state machine (TwoFingerGrasp) or the resultant-force paper's multi-finger
// method over the scene (MultiFingerScene). The loop gives it each fresh sample and the
// time since the previous one and gets back the forces to display.
#include <cstdint>
#include <memory>
#include <span>

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
};

// The first paper's method: index, thumb and wrist.
class TwoFingerEngine final : public GraspEngine {
 public:
  TwoFingerEngine(grasp::ScenePtr scene, const grasp::GraspParameters& parameters = {});
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

 private:
  std::unique_ptr<grasp::TwoFingerGrasp> grasp_;
  int held_ = -1;  // the part in GRASP or MANIPULATE
};

// The resultant-force paper's method with 1–5 fingertips (HandSample::fingertip(k)).
class MultiFingerEngine final : public GraspEngine {
 public:
  MultiFingerEngine(grasp::ScenePtr scene, int fingertips,
                    const grasp::multi_finger::MultiFingerSceneParams& parameters = {});
  const char* name() const noexcept override { return "multi-finger"; }
  int fingertips() const noexcept override { return scene_.fingers(); }
  std::size_t partCount() const noexcept override { return scene_.poses().size(); }
  EngineStep step(const grasp::HandSample& hand, double dt) noexcept override;
  void reset() noexcept override { scene_.reset(); }
  grasp::GraspState state() const noexcept override { return scene_.state(); }
  std::span<const grasp::PartPose> poses() const noexcept override { return scene_.poses(); }
  std::span<const int> moving() const noexcept override { return scene_.carriedParts(); }
  const grasp::Scene& parts() const noexcept override { return scene_.scene(); }
  const grasp::multi_finger::MultiFingerScene& scene() const noexcept { return scene_; }

 private:
  grasp::multi_finger::MultiFingerScene scene_;
};

}  // namespace hg::servo
