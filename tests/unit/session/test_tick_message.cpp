// The recording's per-tick message: every field of a TickRecord survives encode/decode bit
// for bit (NaN, infinities and -0.0 too: replay re-runs the watchdog on them), bytes that
// are not a whole Tick are refused without crashing, the schema written into the file
// decodes the message the way a viewer would, and the message stays small.
#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/dynamic_message.h>
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <iostream>
#include <limits>
#include <memory>
#include <random>

#include "alloc_counter.hpp"
#include "hapticgrasp/session/tick_message.hpp"

namespace hg::session {
namespace {

using servo::TickRecord;
namespace pb = google::protobuf;

constexpr double kInf = std::numeric_limits<double>::infinity();
// A quiet NaN with a payload of its own: a round trip through arithmetic would lose it.
const double kNaN = std::bit_cast<double>(std::uint64_t{0x7FF8'0000'DEAD'BEEFull});

// Distinct values everywhere: a field written into another's place cannot go unnoticed.
struct Counter {
  double n = 0;
  double next() { return n += 1.125; }
  Vec3 vec() { return Vec3(next(), -next(), next()); }
  Mat3 mat() {
    Mat3 m;
    for (int k = 0; k < 9; ++k) m.data()[k] = next();
    return m;
  }
};

device::DeviceCommand command(Counter& c) {
  device::DeviceCommand cmd;
  cmd.f_index = c.vec();
  cmd.f_thumb = c.vec();
  cmd.f_wrist = c.vec();
  cmd.m_wrist = c.vec();
  cmd.f_grasp = c.next();
  for (Vec3& f : cmd.f_extra) f = c.vec();
  return cmd;
}

// Every field set, every slot in use, and the sample as a faulty device gives it.
TickRecord fullRecord() {
  Counter c;
  TickRecord r;
  r.tick = 0x0123'4567'89AB'CDEFull;
  r.time_s = c.next();
  r.dt_s = c.next();
  r.commands = servo::kCommandReset | servo::kCommandPassivityOff;
  r.freshSample = true;
  r.passivityController = true;
  r.saturated = true;
  r.stateBefore = grasp::GraspState::Grasp;
  r.state = grasp::GraspState::Manipulate;
  r.watchdogFault = 3;
  r.events = 0x8000'0041u;
  r.fingertips = 5;
  r.graspedPart = 7;
  grasp::HandSample& hand = r.sample.hand;
  hand.t = -0.0;
  hand.index = Vec3(kNaN, kInf, -kInf);
  hand.thumb = Vec3(-0.0, c.next(), std::numeric_limits<double>::denorm_min());
  hand.wrist = c.vec();
  hand.wristRotation = c.mat();
  hand.wristRotation(1, 2) = kNaN;
  for (Vec3& e : hand.extra) e = c.vec();
  r.sample.jointCount = device::DeviceSample::kMaxJoints;
  for (double& j : r.sample.joints) j = c.next();
  r.sample.buttons = 0xA5A5'0001u;
  r.sample.deviceTime_s = c.next();
  r.raw = command(c);
  r.sent = command(c);
  r.watchdogGain = 0.625;
  for (double& e : r.energy_J) e = c.next();
  for (double& a : r.alpha_Ns_per_m) a = c.next();
  r.compute_us = 12.5f;
  r.deviceIo_us = std::numeric_limits<float>::quiet_NaN();
  r.periodError_us = -3.25f;
  r.scenePublications = 1'234'567'890'123ull;
  r.movingCount = TickRecord::kMaxMoving + 1;  // one more than the record holds: counted
  for (int k = 0; k < TickRecord::kMaxMoving; ++k) {
    r.movingPart[k] = 100 + k;
    r.movingPose[k].rotation = c.mat();
    r.movingPose[k].position = c.vec();
  }
  return r;
}

// A tick as the servo mostly writes them: two fingertips holding a part that moves, the
// passivity controller on, a real wrist rotation.
TickRecord graspTick() {
  Counter c;
  TickRecord r;
  r.tick = 123456;
  r.time_s = 61.7283;
  r.dt_s = 0.000500013;
  r.freshSample = true;
  r.passivityController = true;
  r.stateBefore = r.state = grasp::GraspState::Manipulate;
  r.fingertips = 2;
  r.graspedPart = 0;
  r.sample.hand.t = 61.7281;
  r.sample.hand.index = Vec3(0.1013, 0.0221, 0.3057);
  r.sample.hand.thumb = Vec3(0.0987, -0.0312, 0.2991);
  r.sample.hand.wrist = Vec3(0.0201, -0.0049, 0.3512);
  r.sample.hand.wristRotation = Eigen::AngleAxisd(0.3, Vec3(0.2, 0.5, 1).normalized()).toRotationMatrix();
  r.sample.deviceTime_s = 61.7279;
  r.raw.f_index = Vec3(-2.1, 0.3, 0.8);
  r.raw.f_thumb = Vec3(2.2, -0.25, 0.75);
  r.raw.f_wrist = Vec3(0.01, 0.02, -4.9);
  r.raw.m_wrist = Vec3(0.001, -0.002, 0.0005);
  r.raw.f_grasp = 3.3;
  r.sent = r.raw;
  r.sent.f_index *= 0.97;  // the passivity controller's damping took a little off
  for (int k = 0; k < 3; ++k) r.energy_J[k] = 0.01 * (k + 1) + 1e-7;
  r.alpha_Ns_per_m[0] = 0.4;
  r.compute_us = 38.2f;
  r.deviceIo_us = 4.1f;
  r.periodError_us = 1.7f;
  r.scenePublications = 1;
  r.movingCount = 1;
  r.movingPart[0] = 0;
  r.movingPose[0].rotation = Eigen::AngleAxisd(0.1, Vec3(1, 0.2, 0).normalized()).toRotationMatrix();
  r.movingPose[0].position = Vec3(0.1, 0, 0.3);
  return r;
}

// ---- bit-for-bit comparison, field by field (a record has padding: no memcmp of it) ----

template <class T>
bool sameBits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}
bool sameBits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0; }
bool sameBits(const Mat3& a, const Mat3& b) { return std::memcmp(a.data(), b.data(), 9 * sizeof(double)) == 0; }

#define EXPECT_BITS(field) EXPECT_TRUE(sameBits(a.field, b.field)) << #field

void expectSameCommand(const device::DeviceCommand& a, const device::DeviceCommand& b, const char* which) {
  SCOPED_TRACE(which);
  EXPECT_BITS(f_index);
  EXPECT_BITS(f_thumb);
  EXPECT_BITS(f_wrist);
  EXPECT_BITS(m_wrist);
  EXPECT_BITS(f_grasp);
  for (int k = 0; k < 3; ++k) EXPECT_BITS(f_extra[k]) << k;
}

void expectSameSample(const device::DeviceSample& a, const device::DeviceSample& b) {
  EXPECT_BITS(hand.t);
  EXPECT_BITS(hand.index);
  EXPECT_BITS(hand.thumb);
  EXPECT_BITS(hand.wrist);
  EXPECT_BITS(hand.wristRotation);
  for (int k = 0; k < 3; ++k) EXPECT_BITS(hand.extra[k]) << k;
  for (int k = 0; k < device::DeviceSample::kMaxJoints; ++k) EXPECT_BITS(joints[k]) << k;
  EXPECT_BITS(jointCount);
  EXPECT_BITS(buttons);
  EXPECT_BITS(deviceTime_s);
}

void expectSameRecord(const TickRecord& a, const TickRecord& b) {
  EXPECT_BITS(tick);
  EXPECT_BITS(time_s);
  EXPECT_BITS(dt_s);
  EXPECT_BITS(commands);
  EXPECT_BITS(freshSample);
  EXPECT_BITS(passivityController);
  EXPECT_BITS(saturated);
  EXPECT_BITS(stateBefore);
  EXPECT_BITS(state);
  EXPECT_BITS(watchdogFault);
  EXPECT_BITS(events);
  EXPECT_BITS(fingertips);
  EXPECT_BITS(graspedPart);
  expectSameSample(a.sample, b.sample);
  expectSameCommand(a.raw, b.raw, "raw");
  expectSameCommand(a.sent, b.sent, "sent");
  EXPECT_BITS(watchdogGain);
  for (int k = 0; k < TickRecord::kPorts; ++k) EXPECT_BITS(energy_J[k]) << k;
  for (int k = 0; k < TickRecord::kPorts; ++k) EXPECT_BITS(alpha_Ns_per_m[k]) << k;
  EXPECT_BITS(compute_us);
  EXPECT_BITS(deviceIo_us);
  EXPECT_BITS(periodError_us);
  EXPECT_BITS(scenePublications);
  EXPECT_BITS(movingCount);
  for (int k = 0; k < TickRecord::kMaxMoving; ++k) {
    EXPECT_BITS(movingPart[k]) << k;
    EXPECT_BITS(movingPose[k].rotation) << k;
    EXPECT_BITS(movingPose[k].position) << k;
  }
  EXPECT_BITS(contact.part);
  EXPECT_BITS(contact.carried);
  EXPECT_BITS(contact.unmodelled);
  EXPECT_BITS(contact.letThrough);
  EXPECT_BITS(contact.clearance_m);
  EXPECT_BITS(contact.clearanceExact);
  EXPECT_BITS(contact.otherPart);
  EXPECT_BITS(contact.heldFace);
  EXPECT_BITS(contact.otherFace);
  EXPECT_BITS(contact.heldPoint);
  EXPECT_BITS(contact.otherPoint);
  EXPECT_BITS(contact.penetration_m);
  EXPECT_BITS(contact.contactForce_N);
  EXPECT_BITS(contact.couplingForce_N);
  EXPECT_BITS(contact.couplingTorque_Nm);
  EXPECT_BITS(contact.contacts);
  EXPECT_BITS(contact.active);
  EXPECT_BITS(contact.substeps);
  EXPECT_BITS(contact.queried);
  EXPECT_BITS(contact.lagging);
  EXPECT_BITS(contact.saturated);
  EXPECT_BITS(contact.passivityEnergy_J);
  EXPECT_BITS(contact.rotationalPassivityEnergy_J);
}

TickRecord roundTrip(const TickRecord& r, std::string* bytes = nullptr) {
  std::string encoded;
  encodeTick(r, encoded);
  TickRecord back;
  EXPECT_TRUE(decodeTick(encoded, back));
  if (bytes) *bytes = encoded;
  return back;
}

TEST(TickMessage, EveryFieldRoundTripsBitForBit) {
  const TickRecord r = fullRecord();
  expectSameRecord(r, roundTrip(r));
}

// A carried part in contact with another (the report of contact/contact_report.hpp), and one
// with no part near (its clearance an infinite bound): both come back bit for bit.
TEST(TickMessage, PartToPartContactRoundTripsBitForBit) {
  TickRecord r = graspTick();
  contact::ContactReport& c = r.contact;
  c.part = 0;
  c.carried = 1;
  c.clearance_m = -1.25e-6;  // interference
  c.clearanceExact = true;
  c.otherPart = 3;
  c.heldFace = 5;
  c.otherFace = 12;
  c.heldPoint = Vec3(0.1, 0.2, -0.0000001);
  c.otherPoint = Vec3(0.1, 0.2, 0.0000002);
  c.penetration_m = 1.25e-6;
  c.contactForce_N = Vec3(0, 0.1, 7.9);
  c.couplingForce_N = Vec3(0, 0.1, 7.8);
  c.couplingTorque_Nm = Vec3(-0.0, 0.01, 0);
  c.contacts = 17;
  c.active = 4;
  c.substeps = 2;
  c.queried = 33;
  c.saturated = true;
  c.letThrough = 2;
  c.passivityEnergy_J = 1e-3;
  c.rotationalPassivityEnergy_J = -2e-9;
  expectSameRecord(r, roundTrip(r));
  c = {};
  c.part = 0;
  c.carried = 1;  // no part near: +inf, a bound
  expectSameRecord(r, roundTrip(r));
  EXPECT_TRUE(std::isinf(roundTrip(r).contact.clearance_m));
  c = {};
  c.unmodelled = 1;  // carried without a shell
  expectSameRecord(r, roundTrip(r));
}

TEST(TickMessage, TheComparisonSeesAOneBitDifference) {
  // The test above means something only if a NaN with another payload counts as different.
  TickRecord a = fullRecord(), b = a;
  b.sample.hand.index.x() = std::bit_cast<double>(std::bit_cast<std::uint64_t>(a.sample.hand.index.x()) ^ 1u);
  EXPECT_TRUE(std::isnan(b.sample.hand.index.x()));
  EXPECT_FALSE(sameBits(a.sample.hand.index, b.sample.hand.index));
  b = a;
  b.sample.hand.t = 0.0;  // +0.0 where the record has -0.0
  EXPECT_FALSE(sameBits(a.sample.hand.t, b.sample.hand.t));
}

TEST(TickMessage, LeanFormsRoundTripExactly) {
  // What the encoder leaves out (zero vectors, identity rotations, sent equal to raw, gain 1,
  // trailing zero ports) must come back as exactly what it stood for.
  TickRecord r;
  r.fingertips = 2;
  r.sample.hand.index = Vec3(0.0, 0.0, -0.0);  // -0.0 is not zero to the encoder
  r.watchdogGain = 1.0;
  r.energy_J[0] = 0.5;  // ports 1..5 stay +0.0
  r.raw.f_index = Vec3(1, 2, 3);
  r.sent = r.raw;
  expectSameRecord(r, roundTrip(r));
  r.sent.f_index = Vec3::Zero();  // the watchdog cut the force: sent differs, all zero
  r.watchdogGain = 0.0;
  expectSameRecord(r, roundTrip(r));
}

TEST(TickMessage, SlotsNotInUseDecodeToDefaults) {
  // The ring reuses its records: slots past the counts may hold an earlier tick's values.
  // They are not written, and come back as defaults.
  TickRecord r = fullRecord();
  r.sample.jointCount = 3;
  r.movingCount = 2;
  const TickRecord back = roundTrip(r);
  EXPECT_EQ(back.sample.jointCount, 3);
  EXPECT_EQ(back.sample.joints[2], r.sample.joints[2]);
  EXPECT_EQ(back.sample.joints[3], 0.0);
  EXPECT_EQ(back.movingCount, 2);
  EXPECT_EQ(back.movingPart[1], r.movingPart[1]);
  EXPECT_EQ(back.movingPart[2], 0);
  EXPECT_TRUE(back.movingPose[2].rotation.isIdentity(0));
  EXPECT_TRUE(back.movingPose[2].position.isZero(0));
}

TEST(TickMessage, SizesStayWithinTheRecordingBudget) {
  // Budget: 50 MB/min at 2 kHz after zstd, ~417 B a tick. A stream of manipulating ticks
  // (~515 B each, plus MCAP's 31-byte record header) measured 315-385 B a tick after zstd
  // level 3 (the device fresh every other tick / every tick): inside the budget, not by
  // much. The bounds catch a field that grows the common ticks.
  std::string full, grasp, free;
  roundTrip(fullRecord(), &full);
  roundTrip(graspTick(), &grasp);
  TickRecord idle = graspTick();
  idle.state = idle.stateBefore = grasp::GraspState::Free;
  idle.graspedPart = -1;
  idle.raw = idle.sent = device::DeviceCommand{};
  idle.movingCount = 0;
  std::fill(std::begin(idle.alpha_Ns_per_m), std::end(idle.alpha_Ns_per_m), 0.0);
  roundTrip(idle, &free);
  std::cout << "encoded Tick: " << free.size() << " B free (2 fingertips, no forces), " << grasp.size()
            << " B manipulating (2 fingertips, 1 moving part, passivity on), " << full.size()
            << " B every field (5 fingertips, 16 joints, 8 moving parts)\n";
  EXPECT_LT(free.size(), 280u);
  EXPECT_LT(grasp.size(), 540u);
  EXPECT_LT(free.size(), grasp.size());
  EXPECT_LT(grasp.size(), full.size());
}

TEST(TickMessage, ASteadyStreamAllocatesNothing) {
  // The writer thread encodes up to 8000 ticks a second into one reused buffer.
  std::string out;
  const TickRecord full = fullRecord(), grasp = graspTick();
  encodeTick(full, out);  // the first ticks size the arena and the buffer
  encodeTick(grasp, out);
  const long before = test::allocations();
  for (int k = 0; k < 1000; ++k) encodeTick(k % 2 ? full : grasp, out);
  EXPECT_EQ(test::allocations() - before, 0);
}

TEST(TickMessage, EveryTruncationIsRefusedAndLeavesTheRecordAlone) {
  std::string bytes;
  roundTrip(fullRecord(), &bytes);
  TickRecord out;
  out.tick = 42;
  for (std::size_t n = 0; n < bytes.size(); ++n)
    EXPECT_FALSE(decodeTick(std::string_view(bytes).substr(0, n), out)) << n << " of " << bytes.size();
  EXPECT_EQ(out.tick, 42u);
  // ...and the same for a lean tick, whose fields are mostly absent.
  roundTrip(TickRecord{}, &bytes);
  for (std::size_t n = 0; n < bytes.size(); ++n) EXPECT_FALSE(decodeTick(std::string_view(bytes).substr(0, n), out)) << n;
}

TEST(TickMessage, GarbageIsRefusedWithoutCrashing) {
  std::mt19937 random(20240611);
  std::uniform_int_distribution<int> byte(0, 255), length(0, 600);
  TickRecord out;
  int accepted = 0;
  for (int k = 0; k < 5000; ++k) {
    std::string bytes(static_cast<std::size_t>(length(random)), '\0');
    for (char& b : bytes) b = static_cast<char>(byte(random));
    accepted += decodeTick(bytes, out);
  }
  EXPECT_EQ(accepted, 0);
  // A real message with bytes overwritten may still be a valid tick (a changed double is a
  // double); what matters is that nothing crashes or throws, and that decoding stays consistent.
  std::string real;
  roundTrip(fullRecord(), &real);
  for (int k = 0; k < 5000; ++k) {
    std::string bytes = real;
    for (int flips = 1 + k % 4; flips > 0; --flips)
      bytes[static_cast<std::size_t>(random() % bytes.size())] = static_cast<char>(byte(random));
    if (decodeTick(bytes, out)) {
      EXPECT_GE(out.fingertips, 1);
      EXPECT_LE(out.fingertips, grasp::HandSample::kMaxFingertips);
      EXPECT_LE(out.sample.jointCount, device::DeviceSample::kMaxJoints);
    }
  }
}

TEST(TickMessage, OutOfRangeValuesAreRefused) {
  TickRecord r = fullRecord(), out;
  std::string bytes;
  r.fingertips = 0;
  encodeTick(r, bytes);
  EXPECT_FALSE(decodeTick(bytes, out));
  r = fullRecord();
  r.state = static_cast<grasp::GraspState>(9);
  encodeTick(r, bytes);
  EXPECT_FALSE(decodeTick(bytes, out));
  r = fullRecord();
  encodeTick(r, bytes);
  EXPECT_TRUE(decodeTick(bytes, out));
}

// ---- the schema, used as a viewer uses it ----

TEST(TickMessage, SchemaIsAFileDescriptorSetNamingTick) {
  pb::FileDescriptorSet set;
  ASSERT_TRUE(set.ParseFromString(tickSchema()));
  ASSERT_GE(set.file_size(), 1);
  const pb::FileDescriptorProto& last = set.file(set.file_size() - 1);  // imports come first
  EXPECT_EQ(last.name(), "hapticgrasp/tick.proto");
  EXPECT_EQ(last.package(), "hapticgrasp");
  bool namesTick = false;
  for (const pb::DescriptorProto& m : last.message_type()) namesTick |= m.name() == "Tick";
  EXPECT_TRUE(namesTick);
  EXPECT_EQ(kTickSchemaName, "hapticgrasp.Tick");
}

TEST(TickMessage, SchemaDecodesATickLikeAViewer) {
  // A pool of our own, built only from the schema bytes, as Foxglove builds its decoder.
  pb::FileDescriptorSet set;
  ASSERT_TRUE(set.ParseFromString(tickSchema()));
  pb::DescriptorPool pool;
  for (const pb::FileDescriptorProto& file : set.file()) ASSERT_NE(pool.BuildFile(file), nullptr) << file.name();
  const pb::Descriptor* type = pool.FindMessageTypeByName(std::string(kTickSchemaName));
  ASSERT_NE(type, nullptr);
  pb::DynamicMessageFactory factory(&pool);
  std::unique_ptr<pb::Message> tick(factory.GetPrototype(type)->New());
  const TickRecord r = fullRecord();
  std::string bytes;
  encodeTick(r, bytes);
  ASSERT_TRUE(tick->ParseFromString(bytes));
  const pb::Reflection& refl = *tick->GetReflection();
  EXPECT_TRUE(refl.GetUnknownFields(*tick).empty());  // the schema names every field written

  auto field = [&](const pb::Descriptor* d, const char* name) {
    const pb::FieldDescriptor* f = d->FindFieldByName(name);
    EXPECT_NE(f, nullptr) << name;
    return f;
  };
  EXPECT_EQ(refl.GetUInt64(*tick, field(type, "tick")), r.tick);
  EXPECT_EQ(refl.GetDouble(*tick, field(type, "time_s")), r.time_s);
  EXPECT_EQ(refl.GetInt32(*tick, field(type, "fingertips")), 5);
  EXPECT_EQ(refl.GetEnum(*tick, field(type, "state"))->name(), "MANIPULATE");
  EXPECT_EQ(refl.GetInt32(*tick, field(type, "moving_count")), TickRecord::kMaxMoving + 1);
  EXPECT_EQ(refl.FieldSize(*tick, field(type, "moving")), TickRecord::kMaxMoving);
  const pb::Message& sample = refl.GetMessage(*tick, field(type, "sample"));
  const pb::Message& hand = sample.GetReflection()->GetMessage(sample, field(sample.GetDescriptor(), "hand"));
  const pb::FieldDescriptor* index = field(hand.GetDescriptor(), "index");
  ASSERT_EQ(hand.GetReflection()->FieldSize(hand, index), 3);
  const double x = hand.GetReflection()->GetRepeatedDouble(hand, index, 0);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(x), std::bit_cast<std::uint64_t>(kNaN));  // the payload too
  EXPECT_EQ(hand.GetReflection()->GetRepeatedDouble(hand, index, 1), kInf);

  // What the viewer's decoder holds is the whole tick: written back, it decodes to the record.
  TickRecord back;
  ASSERT_TRUE(decodeTick(tick->SerializeAsString(), back));
  expectSameRecord(r, back);
}

}  // namespace
}  // namespace hg::session
