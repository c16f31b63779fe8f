#pragma once
// 3Dconnexion SpaceMouse as a 6-DOF input that flies a virtual hand (no force output).
//
// Reports (byte 0 = report ID, then int16 little-endian, about +/-350 at full deflection):
//   1: translation x y z  (7 bytes)        or, on newer models, translation + rotation
//      combined (13 bytes: tx ty tz rx ry rz)
//   2: rotation rx ry rz  (7 bytes)
//   3: buttons, a little-endian bit mask (2..13 bytes; the first 4 mask bytes are used)
// Anything else is rejected and counted: short or oversized reports, unknown report IDs,
// and axis values far beyond any real device's range (garbage).
//
// The hand: the deflection, after a deadband, is a velocity (rate control) integrated
// into the wrist's position and rotation; index and thumb sit at +/- half the grip width
// along the wrist's y axis, around a grip centre fixed in the wrist frame. One button
// pinches (the grip closes over gripTime_s), one opens it.
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/device/hid_transport.hpp"

namespace hg::device {

// The known SpaceMouse family by USB vendor/product ID; null when not a SpaceMouse.
const char* spaceMouseModel(std::uint16_t vendor_id, std::uint16_t product_id) noexcept;

struct SpaceMouseModel {
  std::uint16_t vendor_id, product_id;
  const char* name;
};
// Every model spaceMouseModel() knows (the udev rule grants access to each).
std::span<const SpaceMouseModel> spaceMouseModels() noexcept;

struct SpaceMouseStats {
  std::uint64_t accepted = 0;    // reports parsed
  std::uint64_t short_ = 0;      // shorter than their report ID needs (incl. empty)
  std::uint64_t oversized = 0;   // longer than their report ID allows
  std::uint64_t unknownId = 0;   // report IDs the SpaceMouse does not send
  std::uint64_t garbage = 0;     // axis values beyond maxRawMagnitude
  std::uint64_t readErrors = 0;  // the transport returned -1
  std::uint64_t rejected() const { return short_ + oversized + unknownId + garbage; }
};

// The raw device state, updated report by report. No allocation, no throw.
class SpaceMouseParser {
 public:
  static constexpr int kMaxRawMagnitude = 2048;  // real devices stay within about +/-512

  // True when the report was accepted (the state changed or was confirmed).
  bool parse(const std::uint8_t* data, std::size_t size) noexcept;

  const std::array<int, 3>& translation() const noexcept { return translation_; }
  const std::array<int, 3>& rotation() const noexcept { return rotation_; }
  std::uint32_t buttons() const noexcept { return buttons_; }
  const SpaceMouseStats& stats() const noexcept { return stats_; }
  SpaceMouseStats& stats() noexcept { return stats_; }

 private:
  std::array<int, 3> translation_{};
  std::array<int, 3> rotation_{};
  std::uint32_t buttons_ = 0;
  SpaceMouseStats stats_;
};

struct SpaceMouseConfig {
  double fullScale = 350;               // raw counts at full deflection (normalised to 1)
  double deadband = 0.05;               // fraction of full scale, per axis; rescaled beyond
  double linearSpeed_m_per_s = 0.15;    // wrist speed at full deflection
  double angularSpeed_rad_per_s = 1.2;  // wrist turn rate at full deflection
  // Device axes -> absolute frame, for translation and rotation alike. The HID axes are
  // x right, y toward the user, z down; the default gives x right, y away, z up.
  Mat3 axisMap = Vec3(1, -1, -1).asDiagonal();
  bool rotateInWristFrame = false;      // false: turn about absolute axes through the wrist
  Vec3 initialWrist = Vec3(0, -0.15, 0.10);
  Mat3 initialRotation = Mat3::Identity();
  geometry::Aabb workspace{Vec3(-0.5, -0.5, -0.2), Vec3(0.5, 0.5, 0.6)};  // the wrist stays inside
  Vec3 gripCentre_wrist = Vec3(0.08, 0, 0);  // grip centre in the wrist frame
  double openWidth_m = 0.08;            // index-thumb distance, open
  double closedWidth_m = 0.0;           // ... pinched
  double gripTime_s = 0.2;              // full open <-> closed
  int pinchButton = 0;                  // bit in the button mask
  int openButton = 1;
  double inputHold_s = 0.25;            // no report for this long: the deflection is zero
  double maxStep_s = 0.05;              // longest interval integrated in one read
  // DeviceSpec::timeout_s. A SpaceMouse at rest sends nothing, so silence is normal for
  // it; read() still returns false while silent, and the loop decides what a trip means.
  double timeout_s = 1.0;
};

// The virtual hand, integrated from the device state. No allocation, no throw.
class SpaceMouseHand {
 public:
  explicit SpaceMouseHand(const SpaceMouseConfig& config = {});
  void reset() noexcept;

  // Normalised, deadbanded deflection in the absolute frame (each in [-1, 1] per axis).
  void setInput(const std::array<int, 3>& translation, const std::array<int, 3>& rotation,
                std::uint32_t buttons) noexcept;
  // Moves the hand by the current input over dt (clamped to [0, maxStep_s]).
  void advance(double dt) noexcept;
  void fill(grasp::HandSample& hand) const noexcept;

  const Vec3& wrist() const noexcept { return wrist_; }
  Mat3 wristRotation() const noexcept { return rotation_.toRotationMatrix(); }
  double gripWidth() const noexcept { return width_; }
  const Vec3& linearInput() const noexcept { return linear_; }
  const Vec3& angularInput() const noexcept { return angular_; }
  const SpaceMouseConfig& config() const noexcept { return config_; }

 private:
  double shaped(int raw) const noexcept;
  SpaceMouseConfig config_;
  Vec3 wrist_;
  Quat rotation_;
  double width_;
  double targetWidth_;
  Vec3 linear_ = Vec3::Zero(), angular_ = Vec3::Zero();
  std::uint32_t buttons_ = 0;
};

class SpaceMouseDevice : public Device {
 public:
  SpaceMouseDevice(std::unique_ptr<HidConnection> connection, const SpaceMouseConfig& config = {},
                   std::string name = "SpaceMouse");

  const DeviceSpec& spec() const noexcept override { return spec_; }
  // Drains what arrived (nonblocking reads), integrates the hand over the time since the
  // last call, and fills `sample` with it. True only when a valid report arrived, so a
  // silent device keeps returning false and the servo watchdog can trip.
  bool read(DeviceSample& sample) noexcept override;
  // The same with the time given (monotonic, s): for tests and replay.
  bool readAt(DeviceSample& sample, double now_s) noexcept;
  void write(const DeviceCommand&) noexcept override {}  // no force output

  const SpaceMouseParser& parser() const noexcept { return parser_; }
  const SpaceMouseHand& hand() const noexcept { return hand_; }

  static constexpr int kMaxReportsPerRead = 64;

 private:
  std::unique_ptr<HidConnection> connection_;
  SpaceMouseParser parser_;
  SpaceMouseHand hand_;
  DeviceSpec spec_;
  double lastTime_s_ = 0;
  double lastReport_s_ = 0;
  bool started_ = false;
  bool everReported_ = false;
};

}  // namespace hg::device
