#pragma once
// A simulated master arm as a Device, and the simulated operator who moves it.
//
// SimulatedOperator: an intended hand path (index, thumb and wrist positions as a function
// of time, absolute frame; optionally the wrist's orientation too) and a human-like
// joint-space mass-spring-damper that pulls the arm towards it. Each step the Cartesian
// error of the three points (each clamped to maxReach_m, so the operator's push is bounded)
// is turned into a joint step by damped least squares on the stacked 9x10 Jacobian
// [J_i; J_t; J_w(0:3)], or, when the target holds the orientation, 12x10 with the wrist's
// angular rows w J_w(3:6) and the rotation error w r (r the rotation vector of
// R_goal R^T, w = orientationWeight_m),
//   dtheta = J^T (J J^T + lambda^2 I)^-1 e,
// and the operator's joint torque is tau_op = K (.) dtheta - B (.) thetaDot.
//
// SimulatedMasterArm: the arm's rigid-body dynamics (whole-tree mass matrix, Coriolis,
// gravity from the URDF) with the operator's own limb inertia added on the diagonal and a
// little joint friction:
//   (M + M_op) thetaDDot = tau_op + tau_motor - tau_g,true - C thetaDot - b thetaDot,
// integrated with semi-implicit Euler by advance(dt), the joint damping (B of the operator
// and b) implicitly, so firm fingers are stable at sub-steps up to about 1 ms. tau_motor is what the last write()
// commanded (eq 10/25: J^T f + tau_g, saturated to the effort limits), held over the step;
// so the displayed forces push back on the operator and change the motion (closed loop).
// Joint limits are hard stops (position clamped, inward velocity removed).
//
// read, write and advance must be called from one thread (the servo loop calls advance(dt)
// after write(), or a test drives all three). They allocate nothing; the operator's path is a
// std::function and must not allocate either (keyframePath's does not).
#include <functional>
#include <memory>
#include <vector>

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/device/master_arm.hpp"

namespace hg::device {

// Where the operator means the hand to be, absolute frame. With holdOrientation the
// operator also keeps the wrist (hand) frame at wristRotation (wrist frame -> absolute, as
// ArmPose::wristRotation); without it the hand's orientation is left free (the position
// task has a null space there, and squeezed fingers turn the hand).
struct HandTarget {
  Vec3 index = Vec3::Zero();
  Vec3 thumb = Vec3::Zero();
  Vec3 wrist = Vec3::Zero();
  bool holdOrientation = false;
  Mat3 wristRotation = Mat3::Identity();
};
using HandPath = std::function<HandTarget(double t)>;

struct HandKeyframe {
  double t = 0;  // s
  HandTarget target;
};
// Smooth (C1, smoothstep) interpolation between keyframes sorted by time; holds the first
// before and the last after. The orientation is interpolated (along the shortest rotation)
// when both keys hold one; when only one does, the segment holds that key's orientation. Throws std::invalid_argument on an empty or unsorted list.
HandPath keyframePath(std::vector<HandKeyframe> keyframes);

struct OperatorGains {
  // Joint stiffness (N m/rad) and damping (N m s/rad) of the operator's arm and fingers.
  ArmVector stiffness = (ArmVector() << 150, 150, 60, 100, 15, 15, 15, 0.6, 0.6, 0.6).finished();
  ArmVector damping = (ArmVector() << 25, 25, 8, 15, 1.0, 1.0, 1.0, 0.01, 0.01, 0.01).finished();
  // Reflected inertia of the operator's own limb (kg m^2), added to the arm's.
  ArmVector inertia = (ArmVector() << 0.3, 0.3, 0.05, 0.1, 0.01, 0.01, 0.01, 2e-5, 2e-5, 1e-5).finished();
  double dlsLambda = 0.05;  // damping of the least squares (m)
  double maxReach_m = 0.05;  // Cartesian error the operator acts on, per point
  // With HandTarget::holdOrientation: an angular error of 1 rad counts like this many metres
  // of position error (the angular rows of the least squares are scaled by it); the weighted
  // error is clamped to maxReach_m too (so at most maxReach_m / orientationWeight_m rad).
  double orientationWeight_m = 0.2;
};

class SimulatedOperator {
 public:
  explicit SimulatedOperator(HandPath path, OperatorGains gains = {});
  // The operator's joint torques at time t; `kin` is the arm's kinematics with positions in
  // the absolute frame. Allocates nothing.
  void torques(double t, const ArmKinematics& kin, const ArmVector& thetaDot,
               ArmVector& tau) const noexcept;
  HandTarget target(double t) const { return path_ ? path_(t) : HandTarget{}; }
  bool active() const { return static_cast<bool>(path_); }
  const OperatorGains& gains() const { return gains_; }
  // x_w - wrist centre at the arm's resting pose (base frame). The operator pulls the hand
  // at its wrist centre; a target's x_w less this offset (or, holding the orientation, less
  // the offset turned to the target's orientation) is the centre's target.
  void setRestWristOffset(const Vec3& offset) noexcept { restWristOffset_ = offset; }

 private:
  HandPath path_;
  OperatorGains gains_;
  Vec3 restWristOffset_ = Vec3::Zero();
};

struct SimulatedArmOptions {
  std::string urdfPath;                  // empty: ArmModel::defaultUrdfPath()
  Vec3 shoulderPosition{0, 0, 1.4};      // the URDF base in the absolute frame
  ArmVector initialJoints = (ArmVector() << 0.3, 0.0, 0.0, 1.2, 0.0, 0.0, 0.0, 0.3, 0.3, 0.6).finished();
  ArmVector jointFriction = (ArmVector() << 0.2, 0.2, 0.1, 0.1, 0.02, 0.02, 0.02, 2e-4, 2e-4, 2e-4).finished();
  bool gravityCompensation = true;       // false: write() leaves out tau_g (the arm sags)
};

class SimulatedMasterArm final : public Device {
 public:
  // No operator path: nobody holds the arm (only gravity, compensation and displayed forces).
  explicit SimulatedMasterArm(SimulatedArmOptions options = {}, HandPath operatorPath = {},
                              OperatorGains gains = {});

  const DeviceSpec& spec() const noexcept override { return spec_; }
  // The hand from the current joints (absolute frame); false when nothing advanced since
  // the previous read.
  bool read(DeviceSample& sample) noexcept override;
  // Clamps the command to the spec, maps it to joint torques (saturated): eq 25 when it
  // carries a grip force f_g > 0 (its fingertip forces, the same grip force, are left out),
  // eq 10 otherwise.
  void write(const DeviceCommand& command) noexcept override;
  // Integrates the arm and the operator over dt (semi-implicit Euler, damping implicit).
  void advance(double dt) noexcept;

  double time() const { return t_; }
  const ArmVector& joints() const { return theta_; }
  const ArmVector& jointVelocities() const { return thetaDot_; }
  const ArmTorques& lastTorques() const { return lastTorques_; }
  void setJoints(const ArmVector& theta, const ArmVector& thetaDot = ArmVector::Zero());
  // The current hand, absolute frame.
  ArmPose pose() noexcept;
  MasterArm& arm() { return arm_; }
  const SimulatedOperator& simulatedOperator() const { return operator_; }

 private:
  SimulatedArmOptions options_;
  MasterArm arm_;  // used by write() and read() (the servo thread)
  MasterArm sim_;  // used by advance()
  SimulatedOperator operator_;
  DeviceSpec spec_;
  ArmVector theta_, thetaDot_;
  ArmVector tauMotor_ = ArmVector::Zero();
  ArmTorques lastTorques_;
  ArmKinematics kin_, simKin_;
  ArmMatrix mass_;
  double t_ = 0;
  double lastWrite_ = -1e9;
  bool fresh_ = true;
  bool written_ = false;
};

}  // namespace hg::device
