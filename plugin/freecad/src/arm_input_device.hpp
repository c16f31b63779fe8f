#pragma once
// The simulated master arm driven by a live hand target: the front end (the GUI's mouse and
// keyboard hand, a script, a test) sets where the simulated operator means the hand to be,
// and the operator pulls the arm there (device::SimulatedOperator: damped least squares,
// joint spring-damper). The servo loop reads the ARM's fingertips and writes forces that
// are mapped to the arm's joints (eqs 10/25): the grasp sees the arm, not the target.
//
// Threads: setTarget() from any one thread at a time (lock-free, a SeqLock); read() and
// write() on the servo thread only. read() first advances the arm's physics by the time
// elapsed since the previous read (servo::AdvancingArmDevice); the operator's HandPath is
// a closure over a target the servo thread copied out of the SeqLock in read(), so the
// physics never allocates, locks or blocks. A target not set for longer than hold_s counts
// as silence (read() returns false) and the servo watchdog trips, as with HandInputDevice.
//
// Placement: the arm lives in its own frame (servo_bench's: shoulder at (0, 0, 1.4) m); that
// frame is placed in the absolute (document) frame by a turn about the vertical and a
// translation, chosen so that the resting grip centre (midpoint of the index and thumb
// tips) lands on `restGripCentre` and the resting grip axis (horizontal, thumb -> index)
// along `gripAxis` (a horizontal direction; zero: the arm's own). Targets, fingertips and
// forces are converted between the two frames here. The hand opens to about 10 cm.
//
// Orientation: while the grasp holds a part (the last command's f_grasp > 0) the operator
// keeps the hand's orientation, the one the arm's wrist had when the grasp began (as a
// human does; device::HandTarget::holdOrientation). Otherwise the orientation is left free
// unless the target holds one of its own. With only the fingertip and wrist positions the
// orientation is a null space that the squeezed fingers (targets deep inside the part) turn,
// and with it the grasp frame's h2 (eq 17): the carried block turned ~90 deg about the grip
// axis. A fixed orientation from the start (the resting hand pitched to level the
// fingertips) fought the open fingertip targets: the fingertips sat ~10 mm low and the
// index slid under the block while pinching.
#include <atomic>
#include <chrono>
#include <memory>

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/device/simulated_operator.hpp"
#include "hapticgrasp/servo/seqlock.hpp"

namespace hg::servo {
class AdvancingArmDevice;
}

namespace hg::freecad {

class ArmInputDevice final : public device::Device {
 public:
  // fingerFirmness scales the operator's finger stiffness and damping (the bench's 10: the
  // default operator's fingers cannot out-squeeze the grasp's grip force).
  // maxStep_s: the arm's integration sub-step (semi-implicit Euler, damping implicit: the
  // firm fingers are stable up to about 1 ms; with explicit damping they were not above
  // ~0.3 ms, hence the 0.2 ms default, kept as margin).
  explicit ArmInputDevice(const Vec3& restGripCentre, const Vec3& gripAxis = Vec3::Zero(), double hold_s = 0.5,
                          double fingerFirmness = 10, double maxStep_s = 0.2e-3);
  ~ArmInputDevice() override;

  const device::DeviceSpec& spec() const noexcept override { return spec_; }
  bool read(device::DeviceSample& sample) noexcept override;
  void write(const device::DeviceCommand& command) noexcept override;

  // One writer thread at a time: where the operator means the hand to be (absolute frame, m;
  // with holdOrientation, wristRotation: wrist frame -> absolute).
  void setTarget(const device::HandTarget& target) noexcept;
  void setSilent(bool silent) noexcept { silent_.store(silent, std::memory_order_release); }

  // The arm's hand at rest, placed (absolute frame); its grip axis (unit, horizontal,
  // thumb -> index) and the wrist relative to the grip centre at rest (absolute frame).
  const device::ArmPose& restPose() const noexcept { return rest_; }
  Vec3 gripAxis() const noexcept;
  Vec3 restWristOffset() const noexcept;
  // The arm's simulation time (s), any thread.
  double simTime() const noexcept;
  // The largest force written last (N), any thread.
  double lastForce() const noexcept { return lastForce_.load(std::memory_order_acquire); }

 private:
  struct Entry {
    device::HandTarget target;
    double setTime_s = 0;
  };
  double now() const noexcept;

  device::DeviceSpec spec_;
  double hold_s_;
  device::ArmPose rest_;     // absolute frame
  Mat3 yaw_ = Mat3::Identity();  // arm frame -> absolute
  Vec3 origin_ = Vec3::Zero();   // the arm frame's origin, absolute
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  servo::SeqLock<Entry> latest_;
  // Servo thread only: the target the operator pulls to, ARM frame (from latest_ in read()).
  device::HandTarget target_;
  double targetSet_s_ = -1;  // < 0: never set
  bool fedHold_ = false;               // the target set holds an orientation: fedRotation_ (arm frame)
  Mat3 fedRotation_ = Mat3::Identity();
  bool gripHold_ = false;              // grasping: the operator holds heldRotation_ (arm frame)
  Mat3 heldRotation_ = Mat3::Identity();
  Mat3 armWrist_ = Mat3::Identity();   // the arm's wrist orientation at the last read (arm frame)
  // Holding a part the operator makes up for the arm's give under the part's displayed
  // weight, as a person watching the part does: the fed target (fed_, arm frame) is shifted
  // by aim_, which integrates, at kAimRate_per_s while grasping (at most kMaxAim_m), how far
  // the grip centre has fallen behind its fed target since the grasp began (gripLag0_: the
  // lag then, the squeeze's own), and decays at the same rate otherwise.
  Vec3 gripLag_ = Vec3::Zero();   // fed grip centre - the arm's, at the last read (arm frame)
  Vec3 gripLag0_ = Vec3::Zero();
  static constexpr double kAimRate_per_s = 4.0;
  static constexpr double kMaxAim_m = 0.04;
  device::HandTarget fed_;
  Vec3 aim_ = Vec3::Zero();
  double lastSimTime_s_ = -1;
  std::shared_ptr<device::SimulatedMasterArm> arm_;
  std::unique_ptr<servo::AdvancingArmDevice> advancing_;
  std::atomic<bool> silent_{false};
  std::atomic<double> lastForce_{0};
};

}  // namespace hg::freecad
