#pragma once
// A haptic device as the servo loop (core/servo) sees it: read the operator's hand, write the forces
// the grasp computed, and a spec the loop saturates to. Back ends: the simulated master
// arm, simulated and scripted hands, SpaceMouse and generic HID devices, replay.
#include <cstdint>
#include <string>

#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/grasp/hand_sample.hpp"
#include "hapticgrasp/math/types.hpp"

namespace hg::device {

// What the device can do; the servo loop never commands more (SI).
struct DeviceSpec {
  std::string name;
  bool forceOutput = true;           // false: an input-only device (SpaceMouse)
  int fingertips = 2;                // how many HandSample::fingertip(k) it reads (1..5)
  double maxForce_N = 10;            // per fingertip, and at the wrist
  double maxTorque_Nm = 1;           // at the wrist
  double maxStiffness_N_per_m = 2000;  // stable at the servo rate (CHAI3D-style tables)
  double maxDamping_Ns_per_m = 20;
  double timeout_s = 0.05;           // silent longer than this: the watchdog trips
  geometry::Aabb workspace;          // where the hand can be, absolute frame
};

// One reading. `hand` is what the grasp consumes; joints and buttons where the device has them.
struct DeviceSample {
  grasp::HandSample hand;
  static constexpr int kMaxJoints = 16;
  double joints[kMaxJoints] = {};
  int jointCount = 0;
  std::uint32_t buttons = 0;
  double deviceTime_s = 0;  // the device's own clock (monotonic), for the watchdog
};

// The forces and moment to display, absolute frame, as the grasp computed them. In GRASP
// and MANIPULATE the grip force is given twice over: as f_grasp for a device with a grip
// joint (eq 25) and inside f_index / f_thumb (±f_g h1) for one without. A device maps one
// of the two, never both (the simulated arm once did, and its fingers chattered open).
struct DeviceCommand {
  Vec3 f_index = Vec3::Zero();
  Vec3 f_thumb = Vec3::Zero();
  Vec3 f_wrist = Vec3::Zero();
  Vec3 m_wrist = Vec3::Zero();
  double f_grasp = 0;  // between the fingertips (eq 24), for devices with a grip joint
  Vec3 f_extra[grasp::HandSample::kMaxFingertips - 2] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};

  // On fingertip k, numbered as HandSample::fingertip(k).
  const Vec3& fingertipForce(int k) const { return k == 0 ? f_index : k == 1 ? f_thumb : f_extra[k - 2]; }
  Vec3& fingertipForce(int k) { return k == 0 ? f_index : k == 1 ? f_thumb : f_extra[k - 2]; }
};

// Implementations: read() and write() run on the servo thread, so they must not allocate,
// lock for long, or throw; a device that has no new data returns false from read().
class Device {
 public:
  virtual ~Device() = default;
  virtual const DeviceSpec& spec() const noexcept = 0;
  // The latest sample; false when nothing new arrived (the watchdog counts silence).
  virtual bool read(DeviceSample& sample) noexcept = 0;
  virtual void write(const DeviceCommand& command) noexcept = 0;
  // Forces to zero immediately (stop, fault).
  virtual void idle() noexcept { write(DeviceCommand{}); }
};

}  // namespace hg::device
