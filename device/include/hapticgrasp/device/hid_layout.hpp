#pragma once
// A generic HID haptic device described by a JSON layout: where each input lives in the
// input report, and how the force output report is encoded. Example layouts are in
// resources/devices/*.json.
//
//   { "name": "...",
//     "match": {"vendor_id": "0x1234", "product_id": 4660}   or   "path": "/dev/hidraw3",
//     "input_report_id": 1,            // 0 or absent: the device has no numbered reports
//     "report_size": 13,               // bytes, as read (with the report ID byte if numbered)
//     "fields": [ {"name": "wrist.x", "offset": 1, "type": "int16", "endian": "little",
//                  "scale": 0.0001, "bias": 0}, ... ],
//     "force_output": {"report_id": 2, "size": 7,     // bytes incl. the report ID byte 0
//                      "fields": [{"name": "f_wrist.x", "offset": 1, "type": "int16", "scale": 0.01}]},
//     "watchdog_ms": 50,
//     "limits": {"max_force_N": 3, "max_torque_Nm": 0.2, "max_stiffness_N_per_m": 1000,
//                "max_damping_Ns_per_m": 5, "workspace": {"min": [x,y,z], "max": [x,y,z]}},
//     "hand": {"grip_width_m": 0.06, "grip_centre_wrist": [0.08, 0, 0]} }
//
// Input names: index.x|y|z, thumb.x|y|z, fingertip.N.x|y|z (N = 2..4: the multi-finger
// method's further fingertips, HandSample::fingertip(N); they need index.* and thumb.* and
// no gaps; the device's spec then reads N + 1 fingertips), wrist.x|y|z, wrist.roll|pitch|yaw (rad; wrist
// rotation = Rx(roll) Ry(pitch) Rz(yaw)), grip (index-thumb distance, m), buttons (a bit
// mask), button.N (bit N set when non-zero), joint.N (N < 16). value = raw * scale + bias.
// Without index.* and thumb.* fields, the fingertips sit at +/- grip/2 along the wrist's y
// axis around hand.grip_centre_wrist (as the SpaceMouse hand does).
// Output names: f_index.x|y|z, f_thumb.x|y|z, f_fingertip.N.x|y|z, f_wrist.x|y|z, m_wrist.x|y|z, f_grasp;
// raw = (value - bias) / scale, rounded and saturated to the type.
// Offsets count from byte 0 of the report as hidapi gives it, so with numbered reports
// byte 0 is the report ID and no field may sit there.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/device/hid_transport.hpp"

namespace hg::device {

enum class HidFieldType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32 };
enum class HidEndian { Little, Big };
int hidFieldSize(HidFieldType type) noexcept;
const char* hidFieldTypeName(HidFieldType type) noexcept;

struct HidInputField {
  enum class Target { Index, Thumb, Fingertip, Wrist, WristAngle, Grip, Buttons, Button, Joint };
  std::string name;
  Target target = Target::Wrist;
  int component = 0;  // x y z / roll pitch yaw (0..2), button bit, joint number
  int fingertip = 0;  // Target::Fingertip: which one (2..4)
  int offset = 0;
  HidFieldType type = HidFieldType::Int16;
  HidEndian endian = HidEndian::Little;
  double scale = 1, bias = 0;
};

struct HidOutputField {
  enum class Source { FIndex, FThumb, FFingertip, FWrist, MWrist, FGrasp };
  std::string name;
  Source source = Source::FWrist;
  int component = 0;
  int fingertip = 0;  // Source::FFingertip: which one (2..4)
  int offset = 1;
  HidFieldType type = HidFieldType::Int16;
  HidEndian endian = HidEndian::Little;
  double scale = 1, bias = 0;
};

struct HidForceOutput {
  int report_id = 0;
  int size = 0;  // bytes, byte 0 (the report ID) included
  std::vector<HidOutputField> fields;
};

struct HidLayout {
  std::string name;
  std::string source;  // the file it came from, if any
  std::optional<std::uint16_t> vendor_id, product_id;  // product_id absent: any product
  std::string path;                                    // non-empty: match this path only
  int input_report_id = 0;
  int report_size = 0;
  std::vector<HidInputField> fields;
  std::optional<HidForceOutput> force_output;
  double watchdog_ms = 50;
  DeviceSpec spec;  // name, limits, timeout (watchdog) and forceOutput from the layout
  double gripWidth_m = 0.06;
  Vec3 gripCentre_wrist = Vec3(0.08, 0, 0);
  bool directFingertips = false;  // index.* or thumb.* fields given

  bool matches(const HidDeviceInfo& info) const noexcept;
};

// A layout that does not parse or does not make sense. what() is "<source>: <field>:
// <problem>" (no source prefix for text parsed without one); field() is e.g.
// "fields[3].offset" or "force_output.fields[0].type".
class HidLayoutError : public std::runtime_error {
 public:
  HidLayoutError(const std::string& source, std::string field, const std::string& problem);
  const std::string& field() const noexcept { return field_; }

 private:
  std::string field_;
};

HidLayout parseHidLayout(std::string_view jsonText, const std::string& source = "");
HidLayout loadHidLayout(const std::filesystem::path& file);  // HidLayoutError, also for I/O

struct HidLayoutSet {
  std::vector<HidLayout> layouts;
  std::vector<std::string> errors;  // one per file that failed, with its reason
};
// Every *.json in `directory`, sorted by file name; a bad file is reported, not fatal.
HidLayoutSet loadHidLayoutDirectory(const std::filesystem::path& directory);
// The example layouts of the source tree (resources/devices).
std::filesystem::path defaultHidLayoutDirectory();

// Field codecs. decode gives the raw number; encode rounds integers and saturates to the
// type's range (NaN encodes as 0).
double decodeHidValue(const std::uint8_t* bytes, HidFieldType type, HidEndian endian) noexcept;
void encodeHidValue(double raw, std::uint8_t* bytes, HidFieldType type, HidEndian endian) noexcept;

// Decodes an input report into `sample` (hand, buttons, joints; not the times). False,
// leaving `sample` alone, for a report of another ID or the wrong size.
bool decodeInputReport(const HidLayout& layout, const std::uint8_t* data, std::size_t size,
                       DeviceSample& sample) noexcept;

// The command limited to the spec: force vectors to maxForce_N, the moment to
// maxTorque_Nm (direction kept), f_grasp to +/-maxForce_N; anything non-finite to zero.
DeviceCommand saturateCommand(const DeviceCommand& command, const DeviceSpec& spec) noexcept;
// Encodes the (already saturated) command into `out` (capacity `capacity`); returns the
// report size, or 0 when the layout has no force output or `out` is too small.
std::size_t encodeForceReport(const HidLayout& layout, const DeviceCommand& command, std::uint8_t* out,
                              std::size_t capacity) noexcept;
// The inverse, for tests and replay: the command a force report carries (fields absent
// from the layout are zero).
DeviceCommand decodeForceReport(const HidLayout& layout, const std::uint8_t* data, std::size_t size) noexcept;

struct GenericHidStats {
  std::uint64_t accepted = 0;
  std::uint64_t short_ = 0;       // shorter than report_size
  std::uint64_t oversized = 0;    // longer than report_size
  std::uint64_t otherReports = 0; // another report ID (not an error)
  std::uint64_t readErrors = 0;
  std::uint64_t writes = 0;
  std::uint64_t writeErrors = 0;
  std::uint64_t watchdogZeroed = 0;  // writes sent as zero because the input went silent
};

class GenericHidDevice : public Device {
 public:
  GenericHidDevice(std::unique_ptr<HidConnection> connection, HidLayout layout);

  const DeviceSpec& spec() const noexcept override { return layout_.spec; }
  // Drains what arrived (nonblocking); the newest valid report fills `sample`. False, and
  // `sample` untouched, when nothing valid arrived.
  bool read(DeviceSample& sample) noexcept override;
  bool readAt(DeviceSample& sample, double now_s) noexcept;
  // Saturates to the spec and sends the force report. If no input arrived within
  // watchdog_ms, sends zero forces instead (the device's own watchdog).
  void write(const DeviceCommand& command) noexcept override;
  void writeAt(const DeviceCommand& command, double now_s) noexcept;

  const HidLayout& layout() const noexcept { return layout_; }
  const GenericHidStats& stats() const noexcept { return stats_; }

  static constexpr int kMaxReportsPerRead = 64;
  static constexpr std::size_t kMaxReportSize = 256;

 private:
  std::unique_ptr<HidConnection> connection_;
  HidLayout layout_;
  GenericHidStats stats_;
  std::array<std::uint8_t, kMaxReportSize + 1> in_{};
  std::array<std::uint8_t, kMaxReportSize> out_{};
  double lastInput_s_ = -1e300;
};

}  // namespace hg::device
