#pragma once
// Grasping and manipulating a part with two fingertips: the state machine of Maekawa &
// Hollerbach (section 3, Fig. 3), with the errata and hardening of DESIGN.md. One object
// per hand, stepped on the servo thread: step() allocates nothing, throws nothing, locks
// nothing, and is deterministic.
#include <cstdint>
#include <span>
#include <vector>

#include "hapticgrasp/geometry/penetration.hpp"
#include "hapticgrasp/scene/broad_phase.hpp"
#include "hapticgrasp/grasp/force_laws.hpp"
#include "hapticgrasp/grasp/grasp_frame.hpp"
#include "hapticgrasp/grasp/grasp_parameters.hpp"
#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/hand_sample.hpp"
#include "hapticgrasp/scene/model_swaps.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/grasp/rate_filter.hpp"
#include "hapticgrasp/scene/scene.hpp"

namespace hg::grasp {

struct GraspOutput {
  GraspState state = GraspState::Free;
  // GraspEvent bits raised this tick. One tick may raise several: a contact with the grasp
  // it closes; a release with the contact of a fingertip still inside the part.
  std::uint32_t events = 0;
  bool validSample = true;   // false: NaN/Inf in the sample or dt; all forces zero, state kept
  // Fingertip forces on the operator, absolute frame: eq 9 in contact; in GRASP and
  // MANIPULATE the grasping force f_g along +h1 (index) and -h1 (thumb).
  Vec3 f_index = Vec3::Zero();
  Vec3 f_thumb = Vec3::Zero();
  double f_grasp = 0;          // f_g of eq 24 (>= 0, pushes the fingertips apart)
  Vec3 f_wrist = Vec3::Zero(); // eq 23 in GRASP, eq 30 in MANIPULATE
  Vec3 m_wrist = Vec3::Zero();
  int graspedPart = -1;        // in GRASP and MANIPULATE
  int indexPart = -1;          // part each fingertip touches (contact states), else -1
  int thumbPart = -1;
  int queries = 0;             // penetration queries made this tick (box tests are free)
  std::span<const PartPose> poses;  // every part's pose; valid until the next step()
};

class TwoFingerGrasp {
 public:
  // Throws std::invalid_argument for bad parameters or an empty scene pointer.
  TwoFingerGrasp(ScenePtr scene, const GraspParameters& parameters = {});

  // One servo tick: the hand as sampled now, dt seconds after the previous call.
  GraspOutput step(const HandSample& hand, double dt) noexcept;

  // Back to FREE with every part at its initial pose.
  void reset() noexcept;

  GraspState state() const { return state_; }
  const GraspParameters& parameters() const { return k_; }
  const Scene& scene() const { return *scene_; }
  // Part-to-part contact (contact/carried_contact.hpp) stopped the held part short of where
  // the hand put it this tick: it stands at `pose`, and is put down there if released.
  // Nothing when no part is held.
  void placeHeld(const PartPose& pose) noexcept;
  std::span<const PartPose> poses() const { return poses_; }

 private:
  enum Finger { kIndex = 0, kThumb = 1 };

  // One fingertip's contact outside GRASP/MANIPULATE.
  struct Fingertip {
    int part = -1;                 // part in contact, -1 none
    int queryPart = -1;            // part `query` was last used on (its warm start)
    const ScenePart* queryModels = nullptr;  // and its models then (they may be swapped)
    geometry::QueryState query;
    RateFilter depthRate;          // d|p|/dt
    // Outside every part since the last release: only such a fingertip closes a grasp by
    // coming in, so a part put back onto the fingertips is not grasped again at once.
    bool armed = true;
  };

  void stepTouching(const HandSample& hand, double dt, GraspOutput& out) noexcept;
  void stepHolding(const HandSample& hand, GraspOutput& out) noexcept;
  // Contact of one fingertip at x (eq 9): its force and events; queries only the touched
  // part, or else the parts whose box holds x.
  Vec3 touch(Finger finger, const Vec3& x, double dt, GraspOutput& out) noexcept;
  geometry::Penetration query(Fingertip& tip, int part, const Vec3& x, GraspOutput& out) noexcept;
  void beginGrasp(const HandSample& hand, int part, GraspOutput& out) noexcept;
  // Eqs 16-24, 29-30: the held part's pose and the forces, for GRASP or MANIPULATE.
  void hold(const HandSample& hand, GraspOutput& out) noexcept;
  void release(GraspOutput& out) noexcept;
  void setPose(int part, const PartPose& pose) noexcept;
  geometry::Aabb worldBox(int part, const PartPose& pose) const noexcept;
  // Boxes of parts whose models the scene swapped since the last tick (their bounds may differ).
  void refitPublished() noexcept;

  static constexpr int kMaxNear = 64;  // parts queried per free fingertip and tick

  ScenePtr scene_;
  GraspParameters k_;
  // Per-part data, sized once.
  std::vector<PartPose> poses_;
  BroadPhase boxes_;  // absolute boxes at poses_, inflated by boxMargin_m
  ModelSwaps swaps_;  // the scene's model swaps the boxes follow

  GraspState state_ = GraspState::Free;
  Fingertip tips_[2];
  RateFilter distanceRate_;  // d|x_i - x_t|/dt, always running
  bool haveDistance_ = false;
  double pendingDt_ = 0;     // dt of skipped (invalid) ticks, added to the next valid one
  // GRASP / MANIPULATE.
  int held_ = -1;
  const ScenePart* heldModels_ = nullptr;  // the models the grasp began with, kept until release
  GraspMemory memory_;
  Mat3 frame_ = Mat3::Identity();  // last good hand frame (eqs 16-18)
};

}  // namespace hg::grasp
