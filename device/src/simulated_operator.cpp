#include "hapticgrasp/device/simulated_operator.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hapticgrasp/math/rpy.hpp"

namespace hg::device {

HandPath keyframePath(std::vector<HandKeyframe> keyframes) {
  if (keyframes.empty()) throw std::invalid_argument("keyframePath: no keyframes");
  for (std::size_t k = 1; k < keyframes.size(); ++k)
    if (!(keyframes[k].t > keyframes[k - 1].t))
      throw std::invalid_argument("keyframePath: keyframe times must increase");
  auto frames = std::make_shared<const std::vector<HandKeyframe>>(std::move(keyframes));
  return [frames](double t) -> HandTarget {
    const std::vector<HandKeyframe>& f = *frames;
    if (t <= f.front().t) return f.front().target;
    if (t >= f.back().t) return f.back().target;
    const auto next = std::upper_bound(f.begin(), f.end(), t,
                                       [](double v, const HandKeyframe& k) { return v < k.t; });
    const HandKeyframe& b = *next;
    const HandKeyframe& a = *(next - 1);
    double s = (t - a.t) / (b.t - a.t);
    s = s * s * (3 - 2 * s);  // smoothstep: zero velocity at the keyframes
    HandTarget h;
    h.index = a.target.index + s * (b.target.index - a.target.index);
    h.thumb = a.target.thumb + s * (b.target.thumb - a.target.thumb);
    h.wrist = a.target.wrist + s * (b.target.wrist - a.target.wrist);
    if (a.target.holdOrientation && b.target.holdOrientation) {
      h.holdOrientation = true;
      const Vec3 turn = math::rotationVector(b.target.wristRotation * a.target.wristRotation.transpose());
      h.wristRotation = math::fromRotationVector(s * turn) * a.target.wristRotation;
    } else if (a.target.holdOrientation || b.target.holdOrientation) {
      h.holdOrientation = true;
      h.wristRotation = a.target.holdOrientation ? a.target.wristRotation : b.target.wristRotation;
    }
    return h;
  };
}

SimulatedOperator::SimulatedOperator(HandPath path, OperatorGains gains)
    : path_(std::move(path)), gains_(std::move(gains)) {}

namespace {
Vec3 clampNorm(const Vec3& v, double max) {
  const double n = v.norm();
  return n > max ? Vec3(v * (max / n)) : v;
}
}  // namespace

void SimulatedOperator::torques(double t, const ArmKinematics& kin, const ArmVector& thetaDot,
                                ArmVector& tau) const noexcept {
  if (!path_) {
    tau.setZero();
    return;
  }
  const HandTarget goal = path_(t);
  // The operator pulls the hand at its wrist centre c (the URDF's "wrist"), as a person
  // does, and as it did before x_w moved behind the back of the hand: the target's x_w less
  // the resting offset x_w - c (holding the orientation: turned to the target's) is c's target.
  const Vec3& offset = kin.wristCentreOffset;
  const Vec3 goalOffset = goal.holdOrientation && goal.wristRotation.allFinite()
                              ? Vec3(goal.wristRotation * (kin.pose.wristRotation.transpose() * offset))
                              : restWristOffset_;
  const Vec3 wristError = (goal.wrist - goalOffset) - (kin.pose.wrist - offset);
  const double lambda2 = gains_.dlsLambda * gains_.dlsLambda;
  ArmVector step;
  if (goal.holdOrientation && goal.wristRotation.allFinite()) {
    // Position rows as below, and the wrist's angular rows scaled by w: the rotation vector
    // of R_goal R^T (absolute frame, as J_w's angular rows) is the angular error.
    const double w = gains_.orientationWeight_m;
    Eigen::Matrix<double, 12, 1> e;
    e << clampNorm(goal.index - kin.pose.index, gains_.maxReach_m),
        clampNorm(goal.thumb - kin.pose.thumb, gains_.maxReach_m),
        clampNorm(wristError, gains_.maxReach_m),
        clampNorm(w * math::rotationVector(goal.wristRotation * kin.pose.wristRotation.transpose()),
                  gains_.maxReach_m);
    Eigen::Matrix<double, 12, kArmJoints> J;
    J << kin.index, kin.thumb, kin.wristCentre, w * kin.wrist.bottomRows<3>();
    Eigen::Matrix<double, 12, 12> A = J * J.transpose();
    A.diagonal().array() += lambda2;
    const Eigen::Matrix<double, 12, 1> y = A.ldlt().solve(e);
    step = J.transpose() * y;
  } else {
    Eigen::Matrix<double, 9, 1> e;
    e << clampNorm(goal.index - kin.pose.index, gains_.maxReach_m),
        clampNorm(goal.thumb - kin.pose.thumb, gains_.maxReach_m),
        clampNorm(wristError, gains_.maxReach_m);
    Eigen::Matrix<double, 9, kArmJoints> J;
    J << kin.index, kin.thumb, kin.wristCentre;
    Eigen::Matrix<double, 9, 9> A = J * J.transpose();
    A.diagonal().array() += lambda2;
    const Eigen::Matrix<double, 9, 1> y = A.ldlt().solve(e);
    step = J.transpose() * y;
  }
  tau = gains_.stiffness.cwiseProduct(step) - gains_.damping.cwiseProduct(thetaDot);
}

namespace {
std::shared_ptr<const ArmModel> loadModel(const SimulatedArmOptions& o) {
  return ArmModel::fromFile(o.urdfPath.empty() ? ArmModel::defaultUrdfPath() : o.urdfPath);
}
}  // namespace

SimulatedMasterArm::SimulatedMasterArm(SimulatedArmOptions options, HandPath operatorPath,
                                       OperatorGains gains)
    : options_(std::move(options)),
      arm_(loadModel(options_)),
      sim_(arm_.modelPtr()),
      operator_(std::move(operatorPath), std::move(gains)) {
  spec_.name = "simulated master arm";
  spec_.forceOutput = true;
  spec_.maxForce_N = 20;
  spec_.maxTorque_Nm = 2;
  spec_.maxStiffness_N_per_m = 2000;
  spec_.maxDamping_Ns_per_m = 20;
  spec_.timeout_s = 0.05;
  // Reach: upper arm 0.30 + forearm 0.27 + hand to index tip 0.17 m around the shoulder;
  // the box trims the region behind and across the body that the arm cannot reach.
  const Vec3& s = options_.shoulderPosition;
  spec_.workspace = {s + Vec3(-0.35, -0.75, -0.75), s + Vec3(0.75, 0.45, 0.6)};
  setJoints(options_.initialJoints);
}

void SimulatedMasterArm::setJoints(const ArmVector& theta, const ArmVector& thetaDot) {
  const ArmModel& m = arm_.model();
  theta_ = theta.cwiseMax(m.lowerLimits()).cwiseMin(m.upperLimits());
  thetaDot_ = thetaDot;
  fresh_ = true;
  written_ = false;
  arm_.kinematics(theta_, kin_);
  operator_.setRestWristOffset(kin_.wristCentreOffset);
}

ArmPose SimulatedMasterArm::pose() noexcept {
  ArmPose p;
  arm_.forwardKinematics(theta_, p);
  p.index += options_.shoulderPosition;
  p.thumb += options_.shoulderPosition;
  p.wrist += options_.shoulderPosition;
  return p;
}

bool SimulatedMasterArm::read(DeviceSample& sample) noexcept {
  const ArmPose p = pose();
  sample.hand.t = t_;
  sample.hand.index = p.index;
  sample.hand.thumb = p.thumb;
  sample.hand.wrist = p.wrist;
  sample.hand.wristRotation = p.wristRotation;
  sample.jointCount = kArmJoints;
  for (int j = 0; j < kArmJoints; ++j) sample.joints[j] = theta_[j];
  sample.buttons = 0;
  sample.deviceTime_s = t_;
  const bool fresh = fresh_;
  fresh_ = false;
  return fresh;
}

namespace {
Vec3 clampForce(const Vec3& f, double max) {
  if (!f.allFinite()) return Vec3::Zero();
  const double n = f.norm();
  return n > max ? Vec3(f * (max / n)) : f;
}
}  // namespace

void SimulatedMasterArm::write(const DeviceCommand& command) noexcept {
  arm_.kinematics(theta_, kin_);
  ArmVector tau_g = ArmVector::Zero();
  if (options_.gravityCompensation) arm_.gravityTorques(theta_, tau_g);
  const double fg = std::isfinite(command.f_grasp)
                        ? std::clamp(command.f_grasp, -spec_.maxForce_N, spec_.maxForce_N)
                        : 0.0;
  // The arm has a grip Jacobian, so a grasp state's command (f_g > 0) is displayed by eq 25
  // alone: J_w^T [f_w; m_w] + J_g^T f_g. Its fingertip forces are that same grip force
  // again, +-f_g h1 for devices WITHOUT a grip joint (two_finger_grasp.hpp); mapping them
  // too (eq 10) doubled the grip torques on the finger joints, since
  // J_i^T f_g h1 - J_t^T f_g h1 = J_g^T f_g, and kicked the operator's fingers open past
  // d_h: the held part was released and re-grasped many times and dropped mid-lift.
  // Contact states (f_g = 0) map the fingertip forces (eq 10).
  const bool grasping = fg > 0;
  lastTorques_ = arm_.mapTorques(kin_, tau_g, grasping ? Vec3::Zero() : clampForce(command.f_index, spec_.maxForce_N),
                                 grasping ? Vec3::Zero() : clampForce(command.f_thumb, spec_.maxForce_N),
                                 clampForce(command.f_wrist, spec_.maxForce_N),
                                 clampForce(command.m_wrist, spec_.maxTorque_Nm), fg);
  tauMotor_ = lastTorques_.tau;
  lastWrite_ = t_;
  written_ = true;
}

void SimulatedMasterArm::advance(double dt) noexcept {
  if (!(dt > 0) || !std::isfinite(dt)) return;
  const ArmModel& m = sim_.model();
  sim_.kinematics(theta_, simKin_);
  ArmVector tauGravity, coriolis, tauOp;
  sim_.gravityTorques(theta_, tauGravity);  // what holds the arm: physical gravity is -this
  sim_.coriolisTorques(theta_, thetaDot_, coriolis);
  sim_.massMatrix(theta_, mass_);
  mass_.diagonal() += operator_.gains().inertia;
  // The joint damping (the operator's B and the friction b) is integrated implicitly:
  // (M + dt D) thetaDDot = rhs (rhs still has -D thetaDot_n) is thetaDot_{n+1} = thetaDot_n +
  // dt M^-1 (tau - D thetaDot_{n+1}). Explicitly, a finger's B over its tiny inertia
  // (~1e4 /s for the bench's 10x firmer fingers) made steps above ~0.3 ms unstable (dt B / m
  // > 2): at 0.5 ms the fingers oscillated at the joint limits and never grasped. Implicit
  // damping is stable at any step; the stiffness leaves a limit of 2 / omega, milliseconds.
  mass_.diagonal() += dt * (operator_.gains().damping + options_.jointFriction);

  // Motor torques: the last command, held; silent longer than the timeout, the device's own
  // watchdog falls back to gravity compensation only (zero displayed force).
  ArmVector tauMotor = tauMotor_;
  if (!written_ || t_ - lastWrite_ > spec_.timeout_s)
    tauMotor = options_.gravityCompensation ? tauGravity : ArmVector::Zero();

  simKin_.pose.index += options_.shoulderPosition;
  simKin_.pose.thumb += options_.shoulderPosition;
  simKin_.pose.wrist += options_.shoulderPosition;
  operator_.torques(t_, simKin_, thetaDot_, tauOp);

  const ArmVector rhs = tauOp + tauMotor - tauGravity - coriolis -
                        options_.jointFriction.cwiseProduct(thetaDot_);
  const ArmVector acc = mass_.ldlt().solve(rhs);
  thetaDot_ += dt * acc;
  theta_ += dt * thetaDot_;
  for (int j = 0; j < kArmJoints; ++j) {
    if (theta_[j] < m.lowerLimits()[j]) {
      theta_[j] = m.lowerLimits()[j];
      thetaDot_[j] = std::max(0.0, thetaDot_[j]);
    } else if (theta_[j] > m.upperLimits()[j]) {
      theta_[j] = m.upperLimits()[j];
      thetaDot_[j] = std::min(0.0, thetaDot_[j]);
    }
  }
  if (!theta_.allFinite() || !thetaDot_.allFinite()) {  // never hand out NaN: stop the arm
    theta_ = theta_.unaryExpr([](double v) { return std::isfinite(v) ? v : 0.0; });
    thetaDot_.setZero();
  }
  t_ += dt;
  fresh_ = true;
}

}  // namespace hg::device
