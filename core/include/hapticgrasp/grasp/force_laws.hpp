#pragma once
// The force laws of the first paper, section 3, each made non-attractive: a haptic
// contact may push the operator's finger out of a part but never pull it in.
#include "hapticgrasp/grasp/grasp_parameters.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/math/types.hpp"

namespace hg::grasp {

// Eq 9: contact force on a fingertip whose penetration vector is p^a (|p^a| = depth,
// pointing into the part), with d|p|/dt = depthRate. Along -p^a, of magnitude
// max(0, K_c + B_c d|p|/dt) sqrt|p|: when the finger leaves fast the damping would pull,
// so the bracket is clamped at zero. `outward` (unit) is used when |p| is too small to
// give a direction.
Vec3 contactForce(const Vec3& p_a, const Vec3& outward, double depthRate, const GraspParameters& k) noexcept;

// Eq 24 (with |x_i - x_t|, erratum): grasping force f_g >= 0 pushing the fingertips apart,
// for fingertip distance `distance`, its rate, and the distance `graspDistance` at the
// transition to GRASP. Both the damping bracket and the spring's travel are clamped at 0.
double graspingForce(double distance, double distanceRate, double graspDistance, const GraspParameters& k) noexcept;

struct Wrench {
  Vec3 force = Vec3::Zero();   // f_w^a
  Vec3 moment = Vec3::Zero();  // m_w^a
};

// Eq 23: the springs holding a grasped part at its pose at the transition (`held`), with
// the rotational spring chosen by k.rotationalSpring.
Wrench springWrench(const PartPose& pose, const PartPose& held, const GraspParameters& k) noexcept;

// Eq 30: the gravity load of a part of mass M with centre of gravity x_g^o, felt at the
// wrist x_w^a.
Wrench gravityWrench(const PartPose& pose, const Vec3& x_g_o, double mass, const Vec3& wrist,
                     const GraspParameters& k) noexcept;

// Eq 29 corrected (DESIGN.md errata): the springs carry the weight once the wrist force
// along g reaches M |g|^2 -- exactly eq 30's value, so the vertical force is continuous.
bool springsCarryWeight(const Vec3& wristForce, double mass, const GraspParameters& k) noexcept;

}  // namespace hg::grasp
