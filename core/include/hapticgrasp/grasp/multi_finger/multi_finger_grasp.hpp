#pragma once
// The resultant-force paper's 6-DOF method (section 5) for 1–5 fingertips of any device:
// a god object per finger on the part's exact surface (god_object.hpp), the mass-less
// shape shell balanced by the finger springs (shape_shell.hpp, eqs 13–18), the part's mass
// and inertia pulled by a translational and rotational spring-damper towards the shell
// (rigid_body.hpp, section 5.2), and the resultant force and torque distributed over the
// fingers by eq 19 (ResultantDistributor). What eq 19 leaves of the torque about the
// contact normals is taken by torsional (soft-finger) friction, at most μ_t times each
// finger's normal force; beyond that the part slips round in the grasp (the shell turns
// towards the body).
//
// Method::Conventional is the paper's baseline (section 3, eqs 4–8, in 6 DOF): one coupled
// spring model. Each finger's god object sits on the moving part itself and its spring
// f_i = k (p_i − r_i) (plus an optional contact damper, contactDampingRatio) acts straight
// on the part: m a = Σ f_i + f_e, I dω = Σ (r_i − c) × f_i + τ_e, integrated by backward
// Euler on the coupled 6 × 6 system. No shape shell, no eq 19, no torsional friction: each
// finger feels exactly the force its spring gives the part (reversed), so the resultant
// changes the springs' lengths and with them the fingers' distance (eq 8).
//
// step() is allocation-free when the penetration back end is (the exact one is), never
// throws, and ignores non-finite fingertips: usable on the servo thread.
#include <array>
#include <memory>
#include <span>

#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/penetration.hpp"
#include "hapticgrasp/grasp/multi_finger/god_object.hpp"
#include "hapticgrasp/grasp/multi_finger/rigid_body.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/grasp/resultant_distribution.hpp"

namespace hg::grasp::multi_finger {

inline constexpr int kMaxFingers = kMaxDistributionFingers;

enum class Method { Conventional, Proposed };

struct MultiFingerParams {
  Method method = Method::Proposed;
  double stiffness = 800;           // finger–god-object springs k [N/m]
  double friction = 1.0;            // μ
  double torsionalFriction = 0.005; // μ_t [m]: torsional torque limit per newton of normal force
  double dynamicsStiffness = 800;   // k_d [N/m]
  double rotationalStiffness = 0;   // [N m/rad]; ≤ 0: k_d times the part's radius of gyration²
  double dampingRatio = 0.7;        // of both spring-dampers
  double shellVelocityTau = 0.01;   // [s], low-pass of the shell's velocity seen by the dampers
  Vec3 gravity = Vec3(0, 0, -9.81); // [m/s²]
  double contactDampingRatio = 0;   // conventional only: ζ of a damper beside each finger spring
  DistributionParams distribution;
};

struct FingerOutput {
  bool contact = false;
  Vec3 force = Vec3::Zero();    // on the finger, world [N]: grasping + distributed resultant
                                // (conventional: the spring's force, reversed, on the part)
  Vec3 torsion = Vec3::Zero();  // torsional friction torque on the finger, world [N m]
  Vec3 proxy = Vec3::Zero();    // god object, world [m]
  Vec3 normal = Vec3::Zero();   // outward normal at the god object, world
  double graspForce = 0;        // |f_gi| [N] (conventional: |force|)
  double share = 0;             // k_i of eq 19 [N]
};

struct MultiFingerOutput {
  std::array<FingerOutput, kMaxFingers> fingers{};
  int count = 0;
  int contacts = 0;
  PartPose shell, body;                 // conventional: shell = body
  Vec3 resultantForce = Vec3::Zero();   // F: what the fingers must give the part [N]
  Vec3 resultantTorque = Vec3::Zero();  // N about the centre of gravity [N m]
  Vec3 unmatchedForce = Vec3::Zero();   // F − Σ k_i n_i [N]
  Vec3 unmatchedTorque = Vec3::Zero();  // after eq 19 and torsional friction [N m]
  bool slipping = false;                // torsional friction at its limit
};

class MultiFingerGrasp {
 public:
  MultiFingerGrasp(std::shared_ptr<const geometry::PenetrationModel> model, const geometry::MassProperties& mass,
                   int fingers, const MultiFingerParams& params = {});

  void reset(const PartPose& pose) noexcept;
  // Another part, or the same part's newer models (a scene keeps a few of these for the
  // parts the fingers are at): the same as a new MultiFingerGrasp, without allocating.
  // The mass must be positive (the Scene checked it).
  void rebind(std::shared_ptr<const geometry::PenetrationModel> model, const geometry::MassProperties& mass) noexcept;
  // Fingertips in the world frame (count() of them); external force and torque on the part
  // (about its centre of gravity) besides gravity.
  const MultiFingerOutput& step(std::span<const Vec3> fingertips, const Vec3& externalForce,
                                const Vec3& externalTorque, double dt) noexcept;

  // Part-to-part contact stopped the part short of where the tick took it: it stands at
  // `pose` (RigidBody::correct), and the fingers feel the stop through the shell's spring.
  void constrainBody(const PartPose& pose, double dt) noexcept;

  int count() const noexcept { return count_; }
  const MultiFingerOutput& output() const noexcept { return out_; }
  const RigidBody& body() const noexcept { return body_; }

 private:
  void distribute(std::span<const FingerContact> contacts, const Vec3& F, const Vec3& N, const Vec3& centre,
                  std::array<double, kMaxFingers>& share) noexcept;
  const MultiFingerOutput& stepConventional(std::span<const Vec3> tips, const Vec3& externalForce,
                                            const Vec3& externalTorque, double dt) noexcept;

  std::shared_ptr<const geometry::PenetrationModel> model_;
  MultiFingerParams params_;
  int count_;
  std::array<GodObject, kMaxFingers> gods_;
  RigidBody body_;
  ResultantDistributor distributor_;
  ResultantDistributor forceOnly_;  // eq 19 for the force alone, when the cap bites
  PartPose shell_;
  PartPose lastShell_;  // the balanced shell of the last held tick (before its slip turn)
  bool haveLast_ = false;
  Vec3 shellV_ = Vec3::Zero(), shellW_ = Vec3::Zero();
  double radiusOfGyration2_ = 0;
  std::array<Vec3, kMaxFingers> lastTips_{};  // conventional: finger velocities for the dampers
  bool haveTips_ = false;
  MultiFingerOutput out_;
};

}  // namespace hg::grasp::multi_finger
