// HID back ends over the in-process fake transport: SpaceMouse report parsing and the
// virtual hand it flies, generic JSON layouts (parsing, errors, force report codec),
// discovery, silence, and no allocation on the servo path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "hapticgrasp/device/device_discovery.hpp"
#include "hapticgrasp/device/hid_layout.hpp"
#include "hapticgrasp/device/hid_transport.hpp"
#include "hapticgrasp/device/spacemouse.hpp"

using namespace hg;
using namespace hg::device;

namespace {

using Bytes = std::vector<std::uint8_t>;

void put16(Bytes& b, int v) {
  const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
  b.push_back(static_cast<std::uint8_t>(u & 0xff));
  b.push_back(static_cast<std::uint8_t>(u >> 8));
}

Bytes axes(std::uint8_t id, int a, int b, int c) {
  Bytes r{id};
  put16(r, a);
  put16(r, b);
  put16(r, c);
  return r;
}

Bytes combined(int tx, int ty, int tz, int rx, int ry, int rz) {
  Bytes r = axes(1, tx, ty, tz);
  put16(r, rx);
  put16(r, ry);
  put16(r, rz);
  return r;
}

Bytes buttons(std::uint32_t mask) { return {3, static_cast<std::uint8_t>(mask & 0xff), static_cast<std::uint8_t>(mask >> 8)}; }

bool parse(SpaceMouseParser& p, const Bytes& b) { return p.parse(b.data(), b.size()); }

HidDeviceInfo info(const std::string& path, std::uint16_t vid, std::uint16_t pid, const std::string& product,
                   const std::string& manufacturer = "") {
  HidDeviceInfo i;
  i.path = path;
  i.vendor_id = vid;
  i.product_id = pid;
  i.product = product;
  i.manufacturer = manufacturer;
  return i;
}

std::string resource(const std::string& name) { return std::string(HG_RESOURCES_DIR) + "/devices/" + name; }

// The SpaceMouse-style shaping: deadband, rescaled beyond.
double shaped(int raw, const SpaceMouseConfig& c) {
  const double a = std::clamp(raw / c.fullScale, -1.0, 1.0);
  const double m = std::abs(a);
  return m <= c.deadband ? 0 : std::copysign((m - c.deadband) / (1 - c.deadband), a);
}

struct SpaceMouseRig {
  FakeHidTransport fake;
  std::unique_ptr<SpaceMouseDevice> device;
  SpaceMouseConfig config;
  explicit SpaceMouseRig(SpaceMouseConfig c = {}) : config(c) {
    fake.addDevice(info("/dev/hidraw7", 0x046d, 0xc626, "SpaceNavigator", "3Dconnexion"));
    device = std::make_unique<SpaceMouseDevice>(fake.open("/dev/hidraw7"), config);
  }
  void queue(const Bytes& b) { fake.queueReport("/dev/hidraw7", b); }
};

}  // namespace

// ---- SpaceMouse reports ---------------------------------------------------------------

TEST(SpaceMouseParser, SeparateReports) {
  SpaceMouseParser p;
  EXPECT_TRUE(parse(p, axes(1, 100, -200, 350)));
  EXPECT_EQ(p.translation(), (std::array<int, 3>{100, -200, 350}));
  EXPECT_EQ(p.rotation(), (std::array<int, 3>{0, 0, 0}));
  EXPECT_TRUE(parse(p, axes(2, -5, 6, -350)));
  EXPECT_EQ(p.rotation(), (std::array<int, 3>{-5, 6, -350}));
  EXPECT_EQ(p.translation(), (std::array<int, 3>{100, -200, 350}));  // untouched
  EXPECT_TRUE(parse(p, buttons(0x3)));
  EXPECT_EQ(p.buttons(), 0x3u);
  EXPECT_TRUE(parse(p, Bytes{3, 0x00, 0x01}));  // second mask byte: button 8
  EXPECT_EQ(p.buttons(), 0x100u);
  EXPECT_EQ(p.stats().accepted, 4u);
  EXPECT_EQ(p.stats().rejected(), 0u);
}

TEST(SpaceMouseParser, CombinedReport) {
  SpaceMouseParser p;
  EXPECT_TRUE(parse(p, combined(1, -2, 3, -4, 5, -6)));
  EXPECT_EQ(p.translation(), (std::array<int, 3>{1, -2, 3}));
  EXPECT_EQ(p.rotation(), (std::array<int, 3>{-4, 5, -6}));
  // Extremes of int16 encoding survive (within the plausible range).
  EXPECT_TRUE(parse(p, combined(-350, 350, -1, 1, -350, 350)));
  EXPECT_EQ(p.translation(), (std::array<int, 3>{-350, 350, -1}));
  EXPECT_EQ(p.rotation(), (std::array<int, 3>{1, -350, 350}));
}

TEST(SpaceMouseParser, ShortOversizedAndGarbageAreRejectedAndCounted) {
  SpaceMouseParser p;
  ASSERT_TRUE(parse(p, combined(10, 20, 30, 40, 50, 60)));
  ASSERT_TRUE(parse(p, buttons(1)));

  // Short.
  EXPECT_FALSE(p.parse(nullptr, 0));
  EXPECT_FALSE(parse(p, Bytes{}));
  EXPECT_FALSE(parse(p, Bytes{1, 0x10, 0x00}));
  EXPECT_FALSE(parse(p, Bytes{2, 1, 2, 3, 4, 5}));
  EXPECT_FALSE(parse(p, Bytes{3}));
  EXPECT_EQ(p.stats().short_, 5u);

  // Oversized: report 1 neither 7 nor 13 bytes, report 2 not 7, report 3 past 13.
  Bytes r1 = combined(1, 1, 1, 1, 1, 1);
  r1.push_back(0);
  EXPECT_FALSE(parse(p, r1));
  Bytes r1b = axes(1, 1, 1, 1);
  r1b.push_back(0);
  EXPECT_FALSE(parse(p, r1b));
  Bytes r2 = combined(1, 1, 1, 1, 1, 1);
  r2[0] = 2;
  EXPECT_FALSE(parse(p, r2));
  EXPECT_FALSE(parse(p, Bytes(20, 0)));  // id 0: unknown, not oversized
  Bytes r3(20, 0xff);
  r3[0] = 3;
  EXPECT_FALSE(parse(p, r3));
  EXPECT_EQ(p.stats().oversized, 4u);

  // Garbage: unknown IDs and implausible axis values.
  EXPECT_FALSE(parse(p, Bytes{0x17, 1, 2, 3, 4, 5, 6}));
  EXPECT_FALSE(parse(p, Bytes{0xff}));
  EXPECT_EQ(p.stats().unknownId, 3u);
  EXPECT_FALSE(parse(p, axes(1, 32767, 0, 0)));
  EXPECT_FALSE(parse(p, combined(0, 0, 0, 0, 0, -30000)));
  EXPECT_FALSE(parse(p, axes(2, 0, -3000, 0)));
  EXPECT_EQ(p.stats().garbage, 3u);

  // None of that changed the state.
  EXPECT_EQ(p.translation(), (std::array<int, 3>{10, 20, 30}));
  EXPECT_EQ(p.rotation(), (std::array<int, 3>{40, 50, 60}));
  EXPECT_EQ(p.buttons(), 1u);
  EXPECT_EQ(p.stats().accepted, 2u);
  EXPECT_EQ(p.stats().rejected(), 15u);
}

TEST(SpaceMouseParser, RandomBytesNeverCrashAndAreAllAccounted) {
  SpaceMouseParser p;
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> len(0, 64), byte(0, 255);
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    Bytes b(len(rng));
    for (auto& x : b) x = static_cast<std::uint8_t>(byte(rng));
    if (!b.empty() && i % 3 == 0) b[0] = static_cast<std::uint8_t>(1 + i % 3);  // known IDs too
    parse(p, b);
    for (int v : p.translation()) ASSERT_LE(std::abs(v), SpaceMouseParser::kMaxRawMagnitude);
    for (int v : p.rotation()) ASSERT_LE(std::abs(v), SpaceMouseParser::kMaxRawMagnitude);
  }
  EXPECT_EQ(p.stats().accepted + p.stats().rejected(), static_cast<std::uint64_t>(n));
  EXPECT_GT(p.stats().rejected(), static_cast<std::uint64_t>(n / 2));
}

TEST(SpaceMouseParser, ModelTable) {
  EXPECT_STREQ(spaceMouseModel(0x046d, 0xc626), "SpaceNavigator");
  EXPECT_NE(spaceMouseModel(0x256f, 0xc635), nullptr);
  EXPECT_EQ(spaceMouseModel(0x046d, 0xc52b), nullptr);  // a Logitech receiver, not a SpaceMouse
}

// ---- the virtual hand -----------------------------------------------------------------

TEST(SpaceMouseDevice, ConstantInputMovesTheHandAsIntegrated) {
  SpaceMouseRig rig;
  const auto& c = rig.config;
  EXPECT_FALSE(rig.device->spec().forceOutput);
  const int N = 200;
  const double dt = 0.001;
  // Push right (+x), pull toward the user (+y raw = -y absolute), no z.
  DeviceSample s;
  for (int i = 0; i < N; ++i) {
    rig.queue(axes(1, 175, 100, 0));
    EXPECT_TRUE(rig.device->readAt(s, i * dt));
  }
  const double moved = (N - 1) * dt * c.linearSpeed_m_per_s;
  EXPECT_NEAR(s.hand.wrist.x(), c.initialWrist.x() + moved * shaped(175, c), 1e-12);
  EXPECT_NEAR(s.hand.wrist.y(), c.initialWrist.y() - moved * shaped(100, c), 1e-12);
  EXPECT_NEAR(s.hand.wrist.z(), c.initialWrist.z(), 1e-12);
  EXPECT_TRUE(s.hand.wristRotation.isApprox(Mat3::Identity()));
  // Fingertips: the open grip around the grip centre, along the wrist's y.
  EXPECT_NEAR((s.hand.index - s.hand.thumb).norm(), c.openWidth_m, 1e-12);
  EXPECT_TRUE((0.5 * (s.hand.index + s.hand.thumb)).isApprox(s.hand.wrist + c.gripCentre_wrist));
  EXPECT_TRUE(s.hand.finite());
  EXPECT_EQ(rig.device->parser().stats().accepted, static_cast<std::uint64_t>(N));

  // Within the deadband: no motion.
  const Vec3 before = s.hand.wrist;
  for (int i = N; i < 2 * N; ++i) {
    rig.queue(axes(1, 10, -12, 15));
    rig.device->readAt(s, i * dt);
  }
  // The first interval still carries the old input.
  EXPECT_NEAR((s.hand.wrist - before).norm(),
              dt * c.linearSpeed_m_per_s * std::hypot(shaped(175, c), shaped(100, c)), 1e-12);
}

TEST(SpaceMouseDevice, RotationAndCombinedReport) {
  SpaceMouseRig rig;
  const auto& c = rig.config;
  const int N = 101;
  const double dt = 0.002;
  DeviceSample s;
  // Combined report: push down (raw +z -> absolute -z) and twist about raw z.
  for (int i = 0; i < N; ++i) {
    rig.queue(combined(0, 0, 350, 0, 0, 350));
    rig.device->readAt(s, i * dt);
  }
  const double T = (N - 1) * dt;
  EXPECT_NEAR(s.hand.wrist.z(), c.initialWrist.z() - T * c.linearSpeed_m_per_s * shaped(350, c), 1e-12);
  const Mat3 expected = Eigen::AngleAxisd(T * c.angularSpeed_rad_per_s * shaped(350, c), -Vec3::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(s.hand.wristRotation.isApprox(expected, 1e-9)) << s.hand.wristRotation;
  // The grip turned with the wrist.
  const Vec3 h1 = (s.hand.index - s.hand.thumb).normalized();
  EXPECT_TRUE(h1.isApprox(expected.col(1), 1e-9));
}

TEST(SpaceMouseDevice, ButtonsPinchOverAFifthOfASecondAndOpen) {
  SpaceMouseRig rig;
  const auto& c = rig.config;
  const double dt = 0.001;
  DeviceSample s;
  double t = 0;
  rig.queue(buttons(1 << c.pinchButton));
  EXPECT_TRUE(rig.device->readAt(s, t));
  EXPECT_EQ(s.buttons, 1u << c.pinchButton);
  EXPECT_NEAR((s.hand.index - s.hand.thumb).norm(), c.openWidth_m, 1e-12);
  for (int i = 0; i < 100; ++i) rig.device->readAt(s, t += dt);  // 0.1 s: half closed
  EXPECT_NEAR((s.hand.index - s.hand.thumb).norm(), 0.5 * (c.openWidth_m + c.closedWidth_m), 1e-9);
  rig.queue(buttons(0));  // released: stays closing (a latch)
  for (int i = 0; i < 110; ++i) rig.device->readAt(s, t += dt);
  EXPECT_NEAR(rig.device->hand().gripWidth(), c.closedWidth_m, 1e-12);
  EXPECT_NEAR((s.hand.index - s.hand.thumb).norm(), c.closedWidth_m, 1e-12);

  rig.queue(buttons(1 << c.openButton));
  rig.device->readAt(s, t += dt);
  for (int i = 0; i < 50; ++i) rig.device->readAt(s, t += dt);  // 0.05 s: a quarter open
  EXPECT_NEAR(rig.device->hand().gripWidth(), c.closedWidth_m + 0.25 * (c.openWidth_m - c.closedWidth_m), 1e-9);
  for (int i = 0; i < 200; ++i) rig.device->readAt(s, t += dt);
  EXPECT_NEAR(rig.device->hand().gripWidth(), c.openWidth_m, 1e-12);
}

TEST(SpaceMouseDevice, SilentDeviceKeepsReturningFalseAndTheHandStops) {
  SpaceMouseRig rig;
  const auto& c = rig.config;
  DeviceSample s;
  double t = 0;
  rig.queue(axes(1, 350, 0, 0));
  EXPECT_TRUE(rig.device->readAt(s, t));
  const double reportTime = s.deviceTime_s;
  int trues = 0;
  for (int i = 0; i < 1000; ++i) trues += rig.device->readAt(s, t += 0.001);  // 1 s of silence
  EXPECT_EQ(trues, 0);
  EXPECT_EQ(s.deviceTime_s, reportTime);  // the device's clock stood still: the watchdog sees it
  // The stale deflection was held for inputHold_s, then dropped.
  const double held = c.linearSpeed_m_per_s * shaped(350, c) * (c.inputHold_s + 0.001);
  EXPECT_NEAR(s.hand.wrist.x() - c.initialWrist.x(), held, 2e-3 * c.linearSpeed_m_per_s);
  // A read error is counted, and is not new data either.
  rig.fake.queueError("/dev/hidraw7");
  EXPECT_FALSE(rig.device->readAt(s, t += 0.001));
  EXPECT_EQ(rig.device->parser().stats().readErrors, 1u);
  // Garbage only: still false.
  rig.queue(Bytes{0x42, 1, 2});
  EXPECT_FALSE(rig.device->readAt(s, t += 0.001));
  // The real clock path: silent, false, and quick.
  EXPECT_FALSE(rig.device->read(s));
}

TEST(SpaceMouseDevice, WorkspaceClampsTheWrist) {
  SpaceMouseConfig cfg;
  cfg.workspace = geometry::Aabb{Vec3(-0.01, -0.2, 0), Vec3(0.01, 0.2, 0.2)};
  cfg.initialWrist = Vec3(0, 0, 0.1);
  SpaceMouseRig rig(cfg);
  DeviceSample s;
  for (int i = 0; i < 500; ++i) {
    rig.queue(axes(1, 350, 0, 0));
    rig.device->readAt(s, i * 0.01);
  }
  EXPECT_NEAR(s.hand.wrist.x(), 0.01, 1e-12);
}

// ---- generic layouts -------------------------------------------------------------------

TEST(HidLayout, ExampleLayoutsParse) {
  const auto set = loadHidLayoutDirectory(std::string(HG_RESOURCES_DIR) + "/devices");
  EXPECT_TRUE(set.errors.empty()) << set.errors.front();
  ASSERT_GE(set.layouts.size(), 2u);

  const HidLayout joy = loadHidLayout(resource("ff_joystick_3dof.json"));
  EXPECT_EQ(joy.name, "Generic 3-DOF force-feedback joystick");
  ASSERT_TRUE(joy.vendor_id && joy.product_id);
  EXPECT_EQ(*joy.vendor_id, 0x1209);
  EXPECT_EQ(*joy.product_id, 0x0001);
  EXPECT_EQ(joy.input_report_id, 1);
  EXPECT_EQ(joy.report_size, 10);
  ASSERT_EQ(joy.fields.size(), 5u);
  EXPECT_EQ(joy.fields[3].name, "grip");
  EXPECT_EQ(joy.fields[3].type, HidFieldType::UInt8);
  ASSERT_TRUE(joy.force_output);
  EXPECT_EQ(joy.force_output->report_id, 2);
  EXPECT_EQ(joy.force_output->fields.size(), 3u);
  EXPECT_TRUE(joy.spec.forceOutput);
  EXPECT_DOUBLE_EQ(joy.spec.maxForce_N, 4);
  EXPECT_DOUBLE_EQ(joy.spec.timeout_s, 0.05);
  EXPECT_FALSE(joy.directFingertips);

  const HidLayout puck = loadHidLayout(resource("spacemouse_compatible_position.json"));
  EXPECT_FALSE(puck.spec.forceOutput);
  EXPECT_EQ(puck.report_size, 13);
  EXPECT_EQ(puck.fields.size(), 6u);

  // A SpaceMouse combined report decodes as positions through the puck layout.
  DeviceSample s;
  const Bytes r = combined(350, 0, 0, 0, 0, -350);
  ASSERT_TRUE(decodeInputReport(puck, r.data(), r.size(), s));
  EXPECT_NEAR(s.hand.wrist.x(), 0.035, 1e-12);
  EXPECT_NEAR(s.hand.wrist.z(), 0.10, 1e-12);
  EXPECT_TRUE(s.hand.wristRotation.isApprox(Eigen::AngleAxisd(0.35, Vec3::UnitZ()).toRotationMatrix(), 1e-12));
  EXPECT_NEAR((s.hand.index - s.hand.thumb).norm(), 0.06, 1e-12);
  // Report ID 2 or the wrong size: not this layout's report.
  Bytes other = r;
  other[0] = 2;
  EXPECT_FALSE(decodeInputReport(puck, other.data(), other.size(), s));
  EXPECT_FALSE(decodeInputReport(puck, r.data(), 7, s));
}

TEST(HidLayout, ValueCodecs) {
  std::uint8_t b[4];
  for (auto e : {HidEndian::Little, HidEndian::Big}) {
    encodeHidValue(-1234, b, HidFieldType::Int16, e);
    EXPECT_EQ(decodeHidValue(b, HidFieldType::Int16, e), -1234);
    encodeHidValue(70000, b, HidFieldType::Int16, e);  // saturates
    EXPECT_EQ(decodeHidValue(b, HidFieldType::Int16, e), 32767);
    encodeHidValue(-5, b, HidFieldType::UInt16, e);
    EXPECT_EQ(decodeHidValue(b, HidFieldType::UInt16, e), 0);
    encodeHidValue(-3e9, b, HidFieldType::Int32, e);
    EXPECT_EQ(decodeHidValue(b, HidFieldType::Int32, e), -2147483648.0);
    encodeHidValue(4e9, b, HidFieldType::UInt32, e);
    EXPECT_EQ(decodeHidValue(b, HidFieldType::UInt32, e), 4e9);
    encodeHidValue(1.5, b, HidFieldType::Float32, e);
    EXPECT_EQ(decodeHidValue(b, HidFieldType::Float32, e), 1.5);
    encodeHidValue(-129, b, HidFieldType::Int8, e);
    EXPECT_EQ(decodeHidValue(b, HidFieldType::Int8, e), -128);
    encodeHidValue(std::nan(""), b, HidFieldType::UInt8, e);
    EXPECT_EQ(decodeHidValue(b, HidFieldType::UInt8, e), 0);
  }
  encodeHidValue(0x0102, b, HidFieldType::UInt16, HidEndian::Big);
  EXPECT_EQ(b[0], 1);
  EXPECT_EQ(b[1], 2);
  encodeHidValue(0x0102, b, HidFieldType::UInt16, HidEndian::Little);
  EXPECT_EQ(b[0], 2);
  EXPECT_EQ(b[1], 1);
}

namespace {

// A valid base layout, edited by each bad-layout case.
const char* kBase = R"({
  "name": "test",
  "match": {"vendor_id": 4660, "product_id": "0x5678"},
  "input_report_id": 1,
  "report_size": 12,
  "fields": [
    {"name": "index.x", "offset": 1, "type": "int16"},
    {"name": "index.y", "offset": 3, "type": "int16"},
    {"name": "thumb.x", "offset": 5, "type": "int16", "endian": "big", "scale": 0.5, "bias": 1},
    {"name": "buttons", "offset": 10, "type": "uint8"}
  ],
  "force_output": {"report_id": 5, "size": 9, "fields": [
    {"name": "f_index.x", "offset": 1, "type": "int16", "scale": 0.01},
    {"name": "f_grasp", "offset": 3, "type": "float32", "endian": "big"}
  ]},
  "watchdog_ms": 20
})";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

}  // namespace

TEST(HidLayout, EveryErrorNamesItsField) {
  ASSERT_NO_THROW(parseHidLayout(kBase));
  const HidLayout ok = parseHidLayout(kBase);
  EXPECT_TRUE(ok.directFingertips);
  EXPECT_EQ(*ok.vendor_id, 0x1234);
  EXPECT_EQ(*ok.product_id, 0x5678);

  struct Case {
    std::string text, field, message;
  };
  const std::vector<Case> cases = {
      {replaced(kBase, R"("name": "buttons", "offset": 10)", R"("name": "wrist.x", "offset": 14, "type": "int16"})"
                                                              R"(,{"name": "buttons", "offset": 10)"),
       "fields[3].offset", "fields[3].offset: 14 + 2 bytes exceeds report_size 12"},
      {replaced(kBase, R"("offset": 3, "type": "int16")", R"("offset": 3, "type": "int7")"), "fields[1].type",
       "fields[1].type: unknown type 'int7'"},
      {replaced(kBase, R"("name": "index.y")", R"("name": "pinky.y")"), "fields[1].name", "unknown input 'pinky.y'"},
      {replaced(kBase, R"("name": "index.y")", R"("name": "index.x")"), "fields[1].name", "given twice"},
      {replaced(kBase, R"({"name": "index.x", "offset": 1,)", R"({"name": "index.x", "offset": 0,)"),
       "fields[0].offset", "report ID byte"},
      {replaced(kBase, R"({"name": "index.x", "offset": 1,)", R"({"name": "index.x", "offset": -1,)"),
       "fields[0].offset", "out of range"},
      {replaced(kBase, R"({"name": "index.x", "offset": 1,)", R"({"name": "index.x", "offset": "one",)"),
       "fields[0].offset", "expected an integer"},
      {replaced(kBase, R"("endian": "big", "scale": 0.5)", R"("endian": "middle", "scale": 0.5)"), "fields[2].endian",
       "expected \"little\" or \"big\""},
      {replaced(kBase, R"("scale": 0.5)", R"("scale": "half")"), "fields[2].scale", "expected a number"},
      {replaced(kBase, R"("scale": 0.5)", R"("sclae": 0.5)"), "fields[2].sclae", "unknown key"},
      {replaced(kBase, R"("offset": 10, "type": "uint8")", R"("offset": 10, "type": "float32")"), "fields[3].offset",
       "fields[3].offset: 10 + 4 bytes exceeds report_size 12"},
      {replaced(kBase, R"("offset": 10, "type": "uint8")", R"("offset": 8, "type": "float32")"), "fields[3].type",
       "buttons need an integer type"},
      {replaced(kBase, R"("report_size": 12,)", ""), "report_size", "missing"},
      {replaced(kBase, R"("report_size": 12)", R"("report_size": 1000)"), "report_size", "out of range"},
      {replaced(kBase, R"("vendor_id": 4660)", R"("vendor_id": "0xz1")"), "match.vendor_id", "hex string"},
      {replaced(kBase, R"("vendor_id": 4660)", R"("vendor_id": 70000)"), "match.vendor_id", "out of range"},
      {replaced(kBase, R"("match": {"vendor_id": 4660, "product_id": "0x5678"},)", ""), "match", "missing"},
      {replaced(kBase, R"("name": "test",)", ""), "name", "missing"},
      {replaced(kBase, R"({"name": "f_index.x", "offset": 1)", R"({"name": "f_index.w", "offset": 1)"),
       "force_output.fields[0].name", "unknown output 'f_index.w'"},
      {replaced(kBase, R"("offset": 3, "type": "float32")", R"("offset": 6, "type": "float32")"),
       "force_output.fields[1].offset", "force_output.fields[1].offset: 6 + 4 bytes exceeds force_output.size 9"},
      {replaced(kBase, R"("offset": 1, "type": "int16", "scale": 0.01)", R"("offset": 0, "type": "int16", "scale": 0.01)"),
       "force_output.fields[0].offset", "report ID byte"},
      {replaced(kBase, R"("scale": 0.01)", R"("scale": 0)"), "force_output.fields[0].scale", "non-zero"},
      {replaced(kBase, R"("size": 9)", R"("size": "nine")"), "force_output.size", "expected an integer"},
      {replaced(kBase, R"("watchdog_ms": 20)", R"("watchdog_ms": -1)"), "watchdog_ms", "must be in"},
      {replaced(kBase, R"("watchdog_ms": 20)", R"("watchdog_ms": 20, "wachdog": 1)"), "wachdog", "unknown key"},
      {R"({"name": "x", "path": "/dev/hidraw1", "report_size": 4, "fields": []})", "fields", "non-empty array"},
      {R"({"name": "x", "path": 3, "report_size": 4, "fields": []})", "path", "device path"},
      {"{\"name\": \"x\", ", "(json)", "syntax error"},
      {replaced(kBase, R"("watchdog_ms": 20)", R"("watchdog_ms": 1e400)"), "(json)", "number out of range"},
      {"[1, 2]", "(root)", "expected a JSON object"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    try {
      parseHidLayout(c.text, "bad.json");
      ADD_FAILURE() << "case " << i << " (" << c.field << ") parsed";
    } catch (const HidLayoutError& e) {
      EXPECT_EQ(e.field(), c.field) << "case " << i << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << "case " << i << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("bad.json: " + c.field + ": ", 0), 0u) << e.what();
    }
  }
  // A missing file names itself.
  try {
    loadHidLayout("/nonexistent/layout.json");
    ADD_FAILURE();
  } catch (const HidLayoutError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/layout.json"), std::string::npos);
  }
}

TEST(HidLayout, ForceReportRoundTripWithSaturation) {
  const HidLayout L = parseHidLayout(kBase);
  DeviceSpec spec = L.spec;
  spec.maxForce_N = 5;
  DeviceCommand cmd;
  cmd.f_index = Vec3(3, 0, 4) * 2;  // |f| = 10 N -> 5 N
  cmd.f_grasp = 7.25;               // -> 5 N
  const DeviceCommand sat = saturateCommand(cmd, spec);
  EXPECT_NEAR(sat.f_index.norm(), 5, 1e-12);
  EXPECT_TRUE(sat.f_index.normalized().isApprox(cmd.f_index.normalized()));
  EXPECT_EQ(sat.f_grasp, 5);

  std::uint8_t out[32];
  ASSERT_EQ(encodeForceReport(L, sat, out, sizeof out), 9u);
  EXPECT_EQ(out[0], 5);  // report ID
  EXPECT_EQ(encodeForceReport(L, sat, out, 8), 0u);  // too small
  const DeviceCommand back = decodeForceReport(L, out, 9);
  EXPECT_NEAR(back.f_index.x(), 3.0, 0.005);  // int16 at 10 mN
  EXPECT_EQ(back.f_index.y(), 0);             // not in the layout
  EXPECT_EQ(back.f_grasp, 5.0);               // float32, exact

  // The encoding saturates where the spec is wider than the type: 400 N at 10 mN/count.
  DeviceCommand huge;
  huge.f_index = Vec3(-400, 0, 0);
  encodeForceReport(L, huge, out, sizeof out);
  EXPECT_NEAR(decodeForceReport(L, out, 9).f_index.x(), -327.68, 1e-9);

  // Non-finite commands become zero.
  DeviceCommand bad;
  bad.f_index = Vec3(NAN, 1, 1);
  bad.m_wrist = Vec3(INFINITY, 0, 0);
  bad.f_grasp = NAN;
  const DeviceCommand zero = saturateCommand(bad, spec);
  EXPECT_TRUE(zero.f_index.isZero());
  EXPECT_TRUE(zero.m_wrist.isZero());
  EXPECT_EQ(zero.f_grasp, 0);

  // The example joystick: mN int16, saturated to its 4 N.
  const HidLayout joy = loadHidLayout(resource("ff_joystick_3dof.json"));
  DeviceCommand push;
  push.f_wrist = Vec3(0, 0, -9);
  encodeForceReport(joy, saturateCommand(push, joy.spec), out, sizeof out);
  EXPECT_EQ(out[0], 2);
  EXPECT_TRUE(decodeForceReport(joy, out, 7).f_wrist.isApprox(Vec3(0, 0, -4)));
  // Little-endian int16 -4000 at bytes 5..6.
  EXPECT_EQ(out[5], static_cast<std::uint8_t>(static_cast<std::uint16_t>(-4000) & 0xff));
  EXPECT_EQ(out[6], static_cast<std::uint8_t>(static_cast<std::uint16_t>(-4000) >> 8));
}

TEST(GenericHidDevice, ReadsWritesAndWatchdog) {
  FakeHidTransport fake;
  fake.addDevice(info("/dev/hidraw2", 0x1209, 0x0001, "FF stick"));
  const HidLayout joy = loadHidLayout(resource("ff_joystick_3dof.json"));
  GenericHidDevice dev(fake.open("/dev/hidraw2"), joy);
  EXPECT_TRUE(dev.spec().forceOutput);

  auto report = [](int x, int y, int z, int trigger, int buttons) {
    Bytes r = axes(1, x, y, z);
    r.push_back(static_cast<std::uint8_t>(trigger));
    r.push_back(static_cast<std::uint8_t>(buttons));
    r.push_back(0);
    return r;
  };
  DeviceSample s;
  fake.queueReport("/dev/hidraw2", Bytes{1, 2, 3});             // short
  fake.queueReport("/dev/hidraw2", Bytes(11, 1));               // oversized
  fake.queueReport("/dev/hidraw2", Bytes{7, 0, 0, 0, 0, 0, 0, 0, 0, 0});  // other report
  fake.queueReport("/dev/hidraw2", report(1000, -2000, 0, 100, 5));
  ASSERT_TRUE(dev.readAt(s, 1.0));
  EXPECT_EQ(dev.stats().short_, 1u);
  EXPECT_EQ(dev.stats().oversized, 1u);
  EXPECT_EQ(dev.stats().otherReports, 1u);
  EXPECT_EQ(dev.stats().accepted, 1u);
  EXPECT_TRUE(s.hand.wrist.isApprox(Vec3(0.01, -0.02, 0.1)));
  EXPECT_NEAR((s.hand.index - s.hand.thumb).norm(), 0.08 - 0.03, 1e-12);
  EXPECT_EQ(s.buttons, 5u);
  EXPECT_EQ(s.deviceTime_s, 1.0);

  // Forces while the input is alive: saturated and encoded.
  DeviceCommand cmd;
  cmd.f_wrist = Vec3(1, 0, 0);
  dev.writeAt(cmd, 1.01);
  ASSERT_EQ(fake.writes("/dev/hidraw2").size(), 1u);
  EXPECT_TRUE(decodeForceReport(joy, fake.writes("/dev/hidraw2")[0].data(), 7).f_wrist.isApprox(Vec3(1, 0, 0)));

  // Silence: read() keeps returning false, the sample is left alone, and after
  // watchdog_ms the forces written are zero.
  const DeviceSample kept = s;
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(dev.readAt(s, 1.0 + 0.001 * i));
  EXPECT_EQ(s.deviceTime_s, kept.deviceTime_s);
  dev.writeAt(cmd, 1.2);
  EXPECT_TRUE(decodeForceReport(joy, fake.writes("/dev/hidraw2")[1].data(), 7).f_wrist.isZero());
  EXPECT_EQ(dev.stats().watchdogZeroed, 1u);
  dev.idle();
  EXPECT_EQ(fake.writes("/dev/hidraw2").size(), 3u);
  EXPECT_FALSE(dev.read(s));

  // Unplugged: reads and writes error, counted, nothing thrown.
  fake.removeDevice("/dev/hidraw2");
  EXPECT_FALSE(dev.readAt(s, 2.0));
  EXPECT_EQ(dev.stats().readErrors, 1u);
  dev.writeAt(cmd, 2.0);
  EXPECT_EQ(dev.stats().writeErrors, 1u);
}

// A glove with three fingertips: each one read from the report and each one's force
// written back; the spec says it reads three (the multi-finger method's servo loop checks).
TEST(GenericHidDevice, ThreeFingertipGloveReadsAndWritesEveryFingertip) {
  FakeHidTransport fake;
  fake.addDevice(info("/dev/hidraw4", 0x1209, 0x0003, "glove"));
  const HidLayout glove = loadHidLayout(resource("glove_3_fingertips.json"));
  EXPECT_EQ(glove.spec.fingertips, 3);
  GenericHidDevice dev(fake.open("/dev/hidraw4"), glove);
  Bytes r{1};
  for (int v : {1000, 0, 0, -1000, 0, 0, 0, 2000, -500}) put16(r, v);
  r.push_back(0);
  fake.queueReport("/dev/hidraw4", r);
  DeviceSample s;
  ASSERT_TRUE(dev.readAt(s, 1.0));
  EXPECT_TRUE(s.hand.index.isApprox(Vec3(0.01, 0, 0.1)));
  EXPECT_TRUE(s.hand.thumb.isApprox(Vec3(-0.01, 0, 0.1)));
  EXPECT_TRUE(s.hand.fingertip(2).isApprox(Vec3(0, 0.02, 0.095)));

  DeviceCommand cmd;
  cmd.f_index = Vec3(1, 0, 0);
  cmd.fingertipForce(2) = Vec3(0, -2, 9);  // over the glove's 3 N: saturated, direction kept
  dev.writeAt(cmd, 1.01);
  ASSERT_EQ(fake.writes("/dev/hidraw4").size(), 1u);
  const DeviceCommand back = decodeForceReport(glove, fake.writes("/dev/hidraw4")[0].data(), 19);
  EXPECT_TRUE(back.f_index.isApprox(Vec3(1, 0, 0), 1e-3));
  EXPECT_NEAR(back.fingertipForce(2).norm(), 3.0, 2e-3);
  EXPECT_NEAR(back.fingertipForce(2).normalized().dot(Vec3(0, -2, 9).normalized()), 1.0, 1e-6);

  // Further fingertips need the index and the thumb, and no gaps.
  const auto fails = [](const std::string& text, const std::string& message) {
    try {
      parseHidLayout(text);
      ADD_FAILURE() << "parsed: " << message;
    } catch (const HidLayoutError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  fails(R"({"name": "x", "path": "/dev/hidraw1", "report_size": 7, "fields": [
           {"name": "fingertip.2.x", "offset": 1, "type": "int16"}, {"name": "wrist.x", "offset": 3, "type": "int16"}]})",
        "needs index.* and thumb.*");
  fails(R"({"name": "x", "path": "/dev/hidraw1", "report_size": 7, "fields": [
           {"name": "index.x", "offset": 1, "type": "int16"}, {"name": "fingertip.3.x", "offset": 3, "type": "int16"}]})",
        "without fingertip.2");
  fails(R"({"name": "x", "path": "/dev/hidraw1", "report_size": 7, "fields": [
           {"name": "fingertip.5.x", "offset": 1, "type": "int16"}]})",
        "unknown input 'fingertip.5.x'");
}

// ---- discovery ---------------------------------------------------------------------------

TEST(DeviceDiscovery, SpaceMouseUnknownAndLayoutMatches) {
  FakeHidTransport fake;
  fake.addDevice(info("/dev/hidraw0", 0x046d, 0xc626, "SpaceNavigator", "3Dconnexion"));
  fake.addDevice(info("/dev/hidraw1", 0x046d, 0xc52b, "USB Receiver", "Logitech"));
  fake.addDevice(info("/dev/hidraw2", 0x1209, 0x0001, "FF stick"));
  fake.addDevice(info("/dev/hidraw3", 0x256f, 0xc635, "SpaceMouse Compact", "3Dconnexion"));
  std::vector<HidLayout> layouts{loadHidLayout(resource("ff_joystick_3dof.json")),
                                 loadHidLayout(resource("spacemouse_compatible_position.json"))};
  // A layout by path takes a SpaceMouse over.
  layouts.push_back(parseHidLayout(R"({"name": "puck by path", "path": "/dev/hidraw3", "report_size": 13,
      "input_report_id": 1, "fields": [{"name": "wrist.x", "offset": 1, "type": "int16", "scale": 1e-4}]})"));

  const auto found = discoverDevices(fake, layouts);
  ASSERT_EQ(found.size(), 4u);
  EXPECT_EQ(found[0].backend, HidBackend::SpaceMouse);
  EXPECT_EQ(found[0].model, "SpaceNavigator");
  EXPECT_EQ(found[1].backend, HidBackend::None);
  EXPECT_EQ(found[2].backend, HidBackend::GenericLayout);
  EXPECT_EQ(found[2].layoutIndex, 0);
  EXPECT_EQ(found[2].model, "Generic 3-DOF force-feedback joystick");
  EXPECT_EQ(found[3].backend, HidBackend::GenericLayout);
  EXPECT_EQ(found[3].layoutIndex, 2);

  const std::string text = formatDiscoveredDevices(found);
  EXPECT_NE(text.find("/dev/hidraw0  046d:c626  3Dconnexion SpaceNavigator  -> spacemouse (SpaceNavigator)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("046d:c52b  Logitech USB Receiver  -> none (no layout matches)"), std::string::npos) << text;
  EXPECT_NE(text.find("1209:0001  FF stick  -> layout 'Generic 3-DOF force-feedback joystick'"), std::string::npos)
      << text;
  EXPECT_NE(text.find("-> layout 'puck by path'"), std::string::npos) << text;
  EXPECT_EQ(formatDiscoveredDevices({}), "no HID devices found\n");

  // Opening: by back end, with errors for none and for a vanished device.
  auto sm = openDiscoveredDevice(fake, found[0], layouts);
  EXPECT_FALSE(sm->spec().forceOutput);
  EXPECT_NE(sm->spec().name.find("SpaceNavigator"), std::string::npos);
  auto stick = openDiscoveredDevice(fake, found[2], layouts);
  EXPECT_TRUE(stick->spec().forceOutput);
  EXPECT_THROW(openDiscoveredDevice(fake, found[1], layouts), HidError);
  fake.removeDevice("/dev/hidraw0");
  EXPECT_THROW(openDiscoveredDevice(fake, found[0], layouts), HidError);
  EXPECT_THROW(fake.open("/dev/hidraw9"), HidError);
}

TEST(DeviceDiscovery, RealHidapiEnumerationDoesNotThrow) {
  // Whatever this machine has (usually nothing): listing must work and format.
  HidapiTransport real;
  std::vector<DiscoveredDevice> found;
  ASSERT_NO_THROW(found = discoverDevices(real, {}));
  EXPECT_FALSE(formatDiscoveredDevices(found).empty());
  EXPECT_THROW(real.open("/nonexistent/hidraw99"), HidError);
}

// ---- the servo path does not allocate ---------------------------------------------------

TEST(HidDevices, ReadAndWriteDoNotAllocate) {
  {  // the counter counts
    const long c0 = hg::test::allocations();
    auto probe = std::make_unique<std::vector<int>>(100);
    EXPECT_GE(hg::test::allocations() - c0, 2);
  }
  SpaceMouseRig rig;
  const int N = 300;
  for (int i = 0; i < N; ++i) {
    rig.queue(i % 3 == 0 ? axes(1, 100, 0, -50) : i % 3 == 1 ? axes(2, 0, 30, 0) : buttons(i & 1));
    if (i % 10 == 0) rig.queue(Bytes{0x42, 1});  // garbage on the way
  }
  DeviceSample s;
  rig.device->readAt(s, 0);  // warm up
  long before = hg::test::allocations();
  int got = 0;
  for (int i = 1; i <= N + 10; ++i) got += rig.device->readAt(s, i * 0.001);
  got += rig.device->read(s);
  long after = hg::test::allocations();
  EXPECT_EQ(after - before, 0);
  EXPECT_GT(got, 0);

  FakeHidTransport fake;
  fake.addDevice(info("/dev/hidraw2", 0x1209, 0x0001, "FF stick"));
  fake.setRecordWrites("/dev/hidraw2", false);
  GenericHidDevice dev(fake.open("/dev/hidraw2"), loadHidLayout(resource("ff_joystick_3dof.json")));
  for (int i = 0; i < N; ++i) {
    Bytes r = axes(1, i, -i, 2 * i);
    r.insert(r.end(), {10, 1, 0});
    fake.queueReport("/dev/hidraw2", r);
  }
  DeviceCommand cmd;
  cmd.f_wrist = Vec3(1, 2, 30);
  before = hg::test::allocations();
  got = 0;
  for (int i = 0; i < N + 10; ++i) {
    got += dev.readAt(s, i * 0.001);
    dev.writeAt(cmd, i * 0.001);
  }
  dev.write(cmd);
  dev.idle();
  after = hg::test::allocations();
  EXPECT_EQ(after - before, 0);
  EXPECT_GT(got, 0);
  EXPECT_EQ(dev.stats().accepted, static_cast<std::uint64_t>(N));
  EXPECT_EQ(fake.writeCount("/dev/hidraw2"), static_cast<std::size_t>(N + 12));
}
