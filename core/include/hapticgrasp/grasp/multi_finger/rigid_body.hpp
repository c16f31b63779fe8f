#pragma once
// The part's dynamics (the resultant-force paper's sections 4.2 and 5.2): a rigid body
// with the part's mass and inertia (from its B-rep), pulled towards the shape shell by a
// translational and a rotational spring-damper, under gravity and external loads. The
// spring-dampers are integrated implicitly (backward Euler; the gyroscopic term is left
// out), so any stiffness, mass and dt stay bounded. Allocation-free, never throws.
#include <span>

#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/math/types.hpp"

namespace hg::grasp::multi_finger {

struct SpringDamper6 {
  double k = 800;        // translational [N/m]
  double c = 0;          // translational damping [N s/m]
  double kr = 0;         // rotational [N m/rad]
  double cr = 0;         // rotational damping [N m s/rad]
};

class RigidBody {
 public:
  // centre: the centre of gravity in the part frame; inertia about it, part axes.
  RigidBody(double mass, const Vec3& centre, const Mat3& inertia) noexcept;

  void reset(const PartPose& pose) noexcept;
  // One tick towards the shell's pose `target` (the part frame of the shell), moving at
  // targetVelocity / targetAngularVelocity (world), with external force (at the centre of
  // gravity, gravity included by the caller) and torque. Returns the spring-damper's
  // force and torque (about the centre of gravity) on the body after the tick: what the
  // fingers must give the part (eq 9: m ẍ − f_e).
  void step(const PartPose& target, const Vec3& targetVelocity, const Vec3& targetAngularVelocity,
            const SpringDamper6& spring, const Vec3& force, const Vec3& torque, double dt) noexcept;

  // The conventional method's tick (the resultant-force paper's eqs 4–6 in 6 DOF): contact
  // springs and dampers act straight on the body. Contact j at rho[j] from the centre of
  // gravity (world) gives the force f_j = f0[j] − g[j] (v' + ω' × rho[j]) — f0 its spring
  // and damper force at the start of the tick, g = k dt + c its stiffness over the tick —
  // and the torque rho[j] × f_j. Backward Euler on the coupled 6 × 6 system (gyroscopic
  // term left out), so any stiffness and dt stay bounded. Writes the forces applied over
  // the tick (at the new velocities) to applied[j]: m Δv = dt (Σ applied + force) exactly.
  void stepCoupled(std::span<const Vec3> rho, std::span<const Vec3> f0, std::span<const double> g,
                   std::span<Vec3> applied, const Vec3& force, const Vec3& torque, double dt) noexcept;

  // The body may not be where the tick left it (part-to-part contact stopped it short,
  // contact/carried_contact.hpp): it is moved to `pose`, and the velocity it had towards
  // where it would have gone is what it has towards `pose` instead: v += Δx / dt, ω += Δθ / dt,
  // so that a stop leaves no velocity into the obstacle (an inelastic contact, passive).
  void correct(const PartPose& pose, double dt) noexcept;

  const PartPose& pose() const noexcept { return pose_; }
  Vec3 centreWorld() const noexcept { return pose_.pointToAbsolute(centre_); }
  const Vec3& velocity() const noexcept { return v_; }            // of the centre of gravity
  const Vec3& angularVelocity() const noexcept { return w_; }     // world
  const Vec3& springForce() const noexcept { return springForce_; }
  const Vec3& springTorque() const noexcept { return springTorque_; }
  double mass() const noexcept { return m_; }
  const Vec3& centre() const noexcept { return centre_; }

 private:
  double m_;
  Vec3 centre_;
  Mat3 inertia_;
  PartPose pose_;
  Vec3 v_ = Vec3::Zero(), w_ = Vec3::Zero();
  Vec3 springForce_ = Vec3::Zero(), springTorque_ = Vec3::Zero();
};

}  // namespace hg::grasp::multi_finger
