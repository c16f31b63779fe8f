#include "arm_input_device.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "servo/advancing_device.hpp"

namespace hg::freecad {

namespace {
Vec3 gripCentre(const device::ArmPose& p) { return 0.5 * (p.index + p.thumb); }
}  // namespace

ArmInputDevice::ArmInputDevice(const Vec3& restGripCentre, const Vec3& gripAxis, double hold_s, double fingerFirmness,
                               double maxStep_s)
    : hold_s_(hold_s) {
  if (!(hold_s > 0 && std::isfinite(hold_s))) throw std::invalid_argument("arm target hold time must be positive");
  if (!restGripCentre.allFinite() || !gripAxis.allFinite()) throw std::invalid_argument("arm placement must be finite");
  if (!(fingerFirmness > 0 && std::isfinite(fingerFirmness)))
    throw std::invalid_argument("arm finger firmness must be positive");
  device::OperatorGains gains;
  for (int j = device::kIndexFlexion; j <= device::kThumbFlexion; ++j) {
    gains.stiffness[j] *= fingerFirmness;
    gains.damping[j] *= fingerFirmness;
  }
  // Called on the servo thread inside the arm's advance(): copies a member, nothing else.
  device::HandPath path = [this](double) { return target_; };
  arm_ = std::make_shared<device::SimulatedMasterArm>(device::SimulatedArmOptions{}, std::move(path), gains);
  // The placement: the arm's resting grip axis turned onto gripAxis, its grip centre moved
  // onto restGripCentre.
  const device::ArmPose own = arm_->pose();
  target_ = {own.index, own.thumb, own.wrist};  // until the first target: hold still
  fed_ = target_;
  Vec3 u0 = own.index - own.thumb;
  u0.z() = 0;
  Vec3 want(gripAxis.x(), gripAxis.y(), 0);
  if (u0.norm() > 1e-9 && want.norm() > 1e-9)
    yaw_ = Eigen::AngleAxisd(std::atan2(want.y(), want.x()) - std::atan2(u0.y(), u0.x()), Vec3::UnitZ()).toRotationMatrix();
  origin_ = restGripCentre - yaw_ * gripCentre(own);
  rest_.index = yaw_ * own.index + origin_;
  rest_.thumb = yaw_ * own.thumb + origin_;
  rest_.wrist = yaw_ * own.wrist + origin_;
  rest_.wristRotation = yaw_ * own.wristRotation;
  advancing_ = std::make_unique<servo::AdvancingArmDevice>(arm_, maxStep_s);
  spec_ = arm_->spec();
  spec_.name = "simulated arm";
  // The workspace box, placed (the box around the turned box).
  geometry::Aabb box = spec_.workspace;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? box.max.x() : box.min.x(), (c & 2) ? box.max.y() : box.min.y(),
                      (c & 4) ? box.max.z() : box.min.z());
    const Vec3 placed = yaw_ * corner + origin_;
    lo = lo.cwiseMin(placed);
    hi = hi.cwiseMax(placed);
  }
  spec_.workspace.min = lo;
  spec_.workspace.max = hi;
}

ArmInputDevice::~ArmInputDevice() = default;

double ArmInputDevice::now() const noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

Vec3 ArmInputDevice::gripAxis() const noexcept {  // absolute frame
  Vec3 u = rest_.index - rest_.thumb;
  u.z() = 0;
  return u.norm() > 1e-6 ? Vec3(u.normalized()) : Vec3(Vec3::UnitY());
}

Vec3 ArmInputDevice::restWristOffset() const noexcept { return rest_.wrist - gripCentre(rest_); }

double ArmInputDevice::simTime() const noexcept { return advancing_->simTime(); }

void ArmInputDevice::setTarget(const device::HandTarget& target) noexcept {
  Entry entry;
  entry.target = target;
  entry.setTime_s = now();
  latest_.write(entry);
}

bool ArmInputDevice::read(device::DeviceSample& sample) noexcept {
  Entry entry;
  if (latest_.tryRead(entry) && entry.target.index.allFinite() && entry.target.thumb.allFinite() &&
      entry.target.wrist.allFinite()) {
    const Mat3 back = yaw_.transpose();  // absolute -> arm frame
    fed_.index = back * (entry.target.index - origin_);
    fed_.thumb = back * (entry.target.thumb - origin_);
    fed_.wrist = back * (entry.target.wrist - origin_);
    fedHold_ = entry.target.holdOrientation && entry.target.wristRotation.allFinite();
    if (fedHold_) fedRotation_ = back * entry.target.wristRotation;
    targetSet_s_ = entry.setTime_s;
  }
  target_.holdOrientation = gripHold_ || fedHold_;
  target_.wristRotation = gripHold_ ? heldRotation_ : fedRotation_;
  target_.index = fed_.index + aim_;
  target_.thumb = fed_.thumb + aim_;
  target_.wrist = fed_.wrist + aim_;
  // The arm moves on whether or not the front end speaks (it holds the last target).
  const bool fresh = advancing_->read(sample);
  {
    const double t = advancing_->simTime();
    const double dt = lastSimTime_s_ < 0 ? 0.0 : std::clamp(t - lastSimTime_s_, 0.0, 0.05);
    lastSimTime_s_ = t;
    const double a = std::min(1.0, kAimRate_per_s * dt);
    gripLag_ = 0.5 * (fed_.index + fed_.thumb) - 0.5 * (sample.hand.index + sample.hand.thumb);  // arm frame, before the placement below
    if (gripHold_ && gripLag_.allFinite()) {
      aim_ += a * (gripLag_ - gripLag0_);
      if (aim_.norm() > kMaxAim_m) aim_ *= kMaxAim_m / aim_.norm();
    } else {
      aim_ -= a * aim_;
    }
  }
  armWrist_ = sample.hand.wristRotation;  // arm frame
  sample.hand.index = yaw_ * sample.hand.index + origin_;
  sample.hand.thumb = yaw_ * sample.hand.thumb + origin_;
  sample.hand.wrist = yaw_ * sample.hand.wrist + origin_;
  sample.hand.wristRotation = yaw_ * sample.hand.wristRotation;
  if (silent_.load(std::memory_order_acquire)) return false;
  if (targetSet_s_ < 0 || now() - targetSet_s_ > hold_s_) return false;  // not fed: silence
  return fresh;
}

void ArmInputDevice::write(const device::DeviceCommand& command) noexcept {
  const Mat3 back = yaw_.transpose();  // absolute -> arm frame (forces and moments turn only)
  device::DeviceCommand turned = command;
  turned.f_index = back * command.f_index;
  turned.f_thumb = back * command.f_thumb;
  turned.f_wrist = back * command.f_wrist;
  turned.m_wrist = back * command.m_wrist;
  advancing_->write(turned);
  // Holding a part, the operator keeps the hand's orientation from the grasp's start.
  const bool grasping = std::isfinite(command.f_grasp) && command.f_grasp > 0;
  if (grasping && !gripHold_) {
    heldRotation_ = armWrist_;
    gripLag0_ = gripLag_;
  }
  gripHold_ = grasping;
  target_.holdOrientation = gripHold_ || fedHold_;
  target_.wristRotation = gripHold_ ? heldRotation_ : fedRotation_;
  const double f = std::max({command.f_index.norm(), command.f_thumb.norm(), command.f_wrist.norm()});
  lastForce_.store(f, std::memory_order_release);
}

}  // namespace hg::freecad
