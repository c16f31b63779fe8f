#pragma once
// The resultant-force method over a whole scene, for the servo thread: 1–5 fingertips of
// any device touch whichever parts are near; the others cost one box test per fingertip.
//
// The paper's simulation holds its part in the air from the start. A CAD scene has no
// floor and no part-to-part contact, so a part here RESTS where the document put it (a
// support the fingers cannot push it off) until the fingers can carry it:
//
//   resting   the part is fixed; each finger feels its god-object spring (god_object.hpp).
//   carried   the part is the paper's 6-DOF body (MultiFingerGrasp): shape shell, mass,
//             inertia, gravity, eq 19. Entered when two or more fingers squeeze it hard
//             enough for friction to carry its weight: μ · squeeze ≥ m |g|, where the
//             squeeze is the part of the normal forces that cancel one another,
//             Σ|f_n,i| − |Σ f_n,i n_i| (two fingers pressing on the top face squeeze
//             nothing; two opposed ones squeeze 2 f). The analogue of the first paper's
//             lift condition (eq 29 as corrected in DESIGN.md).
//   put down  fewer than two fingers touch a carried part: it rests where it is now.
//
// The scene-level state mirrors the first paper's for the GUI and the recorder: FREE (no
// fingertip touches), INDEX CONTACT (the index alone), THUMB CONTACT (one other fingertip
// alone), GRASP (two or more touch one resting part), MANIPULATE (a part is carried). The
// same event bits: index and thumb contact/detach, grasp, lift, release.
//
// Scale: the parts whose box holds a fingertip come from the scene's broad phase
// (broad_phase.hpp), so a tick costs the same among ten parts or ten thousand. The
// per-part state of the method (god objects, the 6-DOF body) exists only for the parts the
// fingers are at: a pool of kPool states, bound to a part when a fingertip comes near it
// and freed when none is. A part whose models the scene swapped (coarse, then exact) is
// rebound while it rests; a carried part keeps the models it was lifted with until put down.
//
// step() never allocates (the pool is made in the constructor) and never throws;
// non-finite fingertips or dt leave everything as it was and ask for no force.
#include <array>
#include <memory>
#include <span>
#include <vector>

#include "hapticgrasp/scene/broad_phase.hpp"
#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/scene/model_swaps.hpp"
#include "hapticgrasp/grasp/multi_finger/god_object.hpp"
#include "hapticgrasp/grasp/multi_finger/multi_finger_grasp.hpp"
#include "hapticgrasp/scene/scene.hpp"

namespace hg::grasp::multi_finger {

struct MultiFingerSceneParams {
  MultiFingerParams grasp;     // the method, its springs, friction and gravity
  double boxMargin_m = 0.005;  // a part is queried only when a fingertip is this near its box
};

struct MultiFingerSceneOutput {
  GraspState state = GraspState::Free;
  std::uint32_t events = 0;                  // GraspEvent bits raised this tick
  bool validSample = true;                   // false: non-finite input, no force, nothing moved
  int fingers = 0;
  std::array<Vec3, kMaxFingers> force{};     // on each fingertip, world [N]
  std::array<int, kMaxFingers> part{};       // the part each fingertip touches, or -1
  int graspedPart = -1;                      // the carried part (MANIPULATE), or the one squeezed (GRASP)
  int queried = 0;                           // parts whose surfaces were queried this tick
  int unbound = 0;                           // parts near a fingertip left out: the pool was full
  std::span<const PartPose> poses;           // every part's pose; valid until the next step()
};

class MultiFingerScene {
 public:
  // Throws std::invalid_argument for an empty scene pointer or a finger count outside 1–5.
  MultiFingerScene(ScenePtr scene, int fingers, const MultiFingerSceneParams& params = {});

  const MultiFingerSceneOutput& step(std::span<const Vec3> fingertips, double dt) noexcept;
  const Scene& scene() const noexcept { return *scene_; }
  // Every part back at its initial pose, resting; no contact.
  void reset() noexcept;

  int fingers() const noexcept { return fingers_; }
  GraspState state() const noexcept { return out_.state; }
  std::span<const PartPose> poses() const noexcept { return poses_; }
  bool carried(int part) const noexcept;
  // Part-to-part contact (contact/carried_contact.hpp) stopped `part` short of where the last
  // step() took it: it stands at `pose`. Carried, its body is corrected (the fingers feel
  // the stop); just put down, it rests there. No allocation.
  void constrain(int part, const PartPose& pose, double dt) noexcept;
  // The parts carried after the last step(), ascending.
  std::span<const int> carriedParts() const noexcept { return {carriedList_.data(), carriedCount_}; }

  static constexpr int kPool = 16;  // parts the fingers may be at at once

 private:
  // The method's state for one part the fingers are at.
  struct Bound {
    int part = -1;                             // -1: free
    const ScenePart* models = nullptr;         // what it was bound to
    std::unique_ptr<MultiFingerGrasp> method;  // stepped while carried
    std::vector<GodObject> resting;            // one per finger, on the resting part
    double weight_N = 0;
    bool carried = false;
    int contacts = 0;                          // fingers touching it last tick
  };

  // The parts to step this tick, ascending: the carried ones and those near a fingertip.
  int nearParts(std::span<const Vec3> tips, std::array<int, kPool>& parts) noexcept;
  Bound* boundTo(int part) noexcept;
  Bound* bind(int part) noexcept;
  void rebind(Bound& b, int part) noexcept;
  void stepResting(Bound& b, std::span<const Vec3> tips) noexcept;
  void stepCarried(Bound& b, std::span<const Vec3> tips, double dt) noexcept;
  void leave(Bound& b) noexcept;
  void settleState(std::uint32_t& events) noexcept;
  geometry::Aabb worldBox(std::size_t part) const noexcept;
  void refitPublished() noexcept;  // boxes of parts whose models the scene swapped

  ScenePtr scene_;
  int fingers_;
  MultiFingerSceneParams params_;
  std::array<Bound, kPool> pool_;
  std::vector<PartPose> poses_;
  BroadPhase boxes_;  // resting parts' world boxes, inflated by boxMargin_m
  ModelSwaps swaps_;  // the scene's model swaps the boxes follow
  std::array<bool, kMaxFingers> touching_{};
  std::array<int, kPool> carriedList_{};
  std::size_t carriedCount_ = 0;
  MultiFingerSceneOutput out_;
};

}  // namespace hg::grasp::multi_finger
