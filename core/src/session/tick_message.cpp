#include "hapticgrasp/session/tick_message.hpp"

#include <google/protobuf/arena.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <memory>

#include "hapticgrasp/tick.pb.h"
#include "descriptor_set.hpp"

namespace hg::session {
namespace {

namespace pb = google::protobuf;
using Doubles = pb::RepeatedField<double>;
using servo::TickRecord;

// Bit patterns, not values: -0.0 must not pass for +0.0, and NaN must equal itself.
bool sameBits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
bool sameVec(const Vec3& a, const Vec3& b) {
  return sameBits(a.x(), b.x()) && sameBits(a.y(), b.y()) && sameBits(a.z(), b.z());
}

// One arena per thread over a block allocated once: the messages of a tick are built in it
// and the reset before the next tick hands the block back whole, so a stream of ticks
// allocates nothing (16 KiB holds a full tick several times over).
class TickArena {
 public:
  TickArena() : block_(std::make_unique<char[]>(kBlockSize)), arena_(options(block_.get())) {}
  hapticgrasp::Tick* freshTick() {
    arena_.Reset();
    return pb::Arena::CreateMessage<hapticgrasp::Tick>(&arena_);
  }

 private:
  static constexpr std::size_t kBlockSize = 16 * 1024;
  static pb::ArenaOptions options(char* block) {
    pb::ArenaOptions o;
    o.initial_block = block;
    o.initial_block_size = kBlockSize;
    return o;
  }
  std::unique_ptr<char[]> block_;
  pb::Arena arena_;
};

TickArena& threadArena() {
  thread_local TickArena arena;
  return arena;
}

// ---- encoding: the lean forms tick.proto describes ----

void putVec(const Vec3& v, Doubles* out) {
  if (!sameVec(v, Vec3::Zero())) out->Add(v.data(), v.data() + 3);
}

void putRotation(const Mat3& m, Doubles* out) {
  const Mat3 identity = Mat3::Identity();
  bool isIdentity = true;
  for (int k = 0; k < 9; ++k) isIdentity = isIdentity && sameBits(m.data()[k], identity.data()[k]);
  if (isIdentity) return;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) out->Add(m(row, col));
}

void putPorts(const double (&v)[TickRecord::kPorts], Doubles* out) {
  int n = TickRecord::kPorts;
  while (n > 0 && sameBits(v[n - 1], 0.0)) --n;
  out->Add(v, v + n);
}

void putSample(const device::DeviceSample& s, hapticgrasp::DeviceSample* out) {
  hapticgrasp::HandSample* hand = out->mutable_hand();
  hand->set_t(s.hand.t);
  putVec(s.hand.index, hand->mutable_index());
  putVec(s.hand.thumb, hand->mutable_thumb());
  putVec(s.hand.wrist, hand->mutable_wrist());
  putRotation(s.hand.wristRotation, hand->mutable_wrist_rotation());
  putVec(s.hand.extra[0], hand->mutable_middle());
  putVec(s.hand.extra[1], hand->mutable_ring());
  putVec(s.hand.extra[2], hand->mutable_little());
  const int joints = std::clamp(s.jointCount, 0, device::DeviceSample::kMaxJoints);
  out->mutable_joints()->Add(s.joints, s.joints + joints);
  out->set_buttons(s.buttons);
  out->set_device_time_s(s.deviceTime_s);
}

// A command written as what differs from `base` (zero for raw, raw for sent): the sent
// command usually differs from the raw one in a vector or two, if at all.
void putChange(const Vec3& v, const Vec3& base, Doubles* out) {
  if (!sameVec(v, base)) out->Add(v.data(), v.data() + 3);
}
void putCommand(const device::DeviceCommand& c, const device::DeviceCommand& base, hapticgrasp::DeviceCommand* out) {
  putChange(c.f_index, base.f_index, out->mutable_f_index());
  putChange(c.f_thumb, base.f_thumb, out->mutable_f_thumb());
  putChange(c.f_wrist, base.f_wrist, out->mutable_f_wrist());
  putChange(c.m_wrist, base.m_wrist, out->mutable_m_wrist());
  if (!sameBits(c.f_grasp, base.f_grasp)) out->set_f_grasp(c.f_grasp);
  putChange(c.f_extra[0], base.f_extra[0], out->mutable_f_middle());
  putChange(c.f_extra[1], base.f_extra[1], out->mutable_f_ring());
  putChange(c.f_extra[2], base.f_extra[2], out->mutable_f_little());
}

bool sameCommand(const device::DeviceCommand& a, const device::DeviceCommand& b) {
  bool same = sameVec(a.f_index, b.f_index) && sameVec(a.f_thumb, b.f_thumb) && sameVec(a.f_wrist, b.f_wrist) &&
              sameVec(a.m_wrist, b.m_wrist) && sameBits(a.f_grasp, b.f_grasp);
  for (int k = 0; k < 3; ++k) same = same && sameVec(a.f_extra[k], b.f_extra[k]);
  return same;
}

void putMoving(const TickRecord& r, hapticgrasp::Tick& t) {
  t.set_moving_count(r.movingCount);
  const int n = std::clamp(r.movingCount, 0, TickRecord::kMaxMoving);
  for (int k = 0; k < n; ++k) {
    hapticgrasp::MovingPart* part = t.add_moving();
    part->set_part(r.movingPart[k]);
    putRotation(r.movingPose[k].rotation, part->mutable_rotation());
    putVec(r.movingPose[k].position, part->mutable_position());
  }
}

// Written only when something was carried with contact: the usual tick stays as lean.
void putContact(const contact::ContactReport& c, hapticgrasp::Tick& t) {
  if (c.part < 0 && c.carried == 0 && c.unmodelled == 0) return;
  hapticgrasp::Contact& m = *t.mutable_contact();
  m.set_part(c.part);
  m.set_carried(c.carried);
  m.set_unmodelled(c.unmodelled);
  m.set_let_through(c.letThrough);
  m.set_clearance_m(c.clearance_m);
  m.set_clearance_exact(c.clearanceExact);
  m.set_other_part(c.otherPart);
  m.set_held_face(c.heldFace);
  m.set_other_face(c.otherFace);
  putVec(c.heldPoint, m.mutable_held_point());
  putVec(c.otherPoint, m.mutable_other_point());
  m.set_penetration_m(c.penetration_m);
  putVec(c.contactForce_N, m.mutable_contact_force_n());
  putVec(c.couplingForce_N, m.mutable_coupling_force_n());
  putVec(c.couplingTorque_Nm, m.mutable_coupling_torque_nm());
  m.set_contacts(c.contacts);
  m.set_active(c.active);
  m.set_substeps(c.substeps);
  m.set_queried(c.queried);
  m.set_lagging(c.lagging);
  m.set_saturated(c.saturated);
  m.set_passivity_energy_j(c.passivityEnergy_J);
  m.set_rotational_passivity_energy_j(c.rotationalPassivityEnergy_J);
}

void putTick(const TickRecord& r, hapticgrasp::Tick& t) {
  t.set_tick(r.tick);
  t.set_time_s(r.time_s);
  t.set_dt_s(r.dt_s);
  t.set_commands(r.commands);
  t.set_fresh_sample(r.freshSample);
  t.set_passivity_controller(r.passivityController);
  t.set_saturated(r.saturated);
  t.set_state_before(static_cast<hapticgrasp::GraspState>(r.stateBefore));
  t.set_state(static_cast<hapticgrasp::GraspState>(r.state));
  t.set_watchdog_fault(r.watchdogFault);
  t.set_events(r.events);
  t.set_grasped_part(r.graspedPart);
  putSample(r.sample, t.mutable_sample());
  putCommand(r.raw, device::DeviceCommand{}, t.mutable_raw());
  if (!sameCommand(r.sent, r.raw)) putCommand(r.sent, r.raw, t.mutable_sent());
  if (!sameBits(r.watchdogGain, 1.0)) t.set_watchdog_gain(r.watchdogGain);
  putPorts(r.energy_J, t.mutable_energy_j());
  putPorts(r.alpha_Ns_per_m, t.mutable_alpha_ns_per_m());
  t.set_compute_us(r.compute_us);
  t.set_device_io_us(r.deviceIo_us);
  t.set_period_error_us(r.periodError_us);
  t.set_scene_publications(r.scenePublications);
  putMoving(r, t);
  putContact(r.contact, t);
  t.set_fingertips(r.fingertips);
}

// ---- decoding: each getter refuses a form encodeTick never writes ----

bool getVec(const Doubles& f, Vec3& v) {
  if (f.empty()) v = Vec3::Zero();
  else if (f.size() == 3) v = Vec3(f[0], f[1], f[2]);
  else return false;
  return true;
}

// A vector written by putChange: empty keeps v as it is (the base).
bool getChange(const Doubles& f, Vec3& v) { return f.empty() || getVec(f, v); }

bool getRotation(const Doubles& f, Mat3& m) {
  if (f.empty()) {
    m = Mat3::Identity();
    return true;
  }
  if (f.size() != 9) return false;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) m(row, col) = f[3 * row + col];
  return true;
}

bool getPorts(const Doubles& f, double (&v)[TickRecord::kPorts]) {
  if (f.size() > TickRecord::kPorts) return false;
  std::fill(std::begin(v), std::end(v), 0.0);
  std::copy(f.begin(), f.end(), v);
  return true;
}

bool getSample(const hapticgrasp::DeviceSample& in, device::DeviceSample& s) {
  const hapticgrasp::HandSample& hand = in.hand();
  s.hand.t = hand.t();
  if (in.joints_size() > device::DeviceSample::kMaxJoints) return false;
  s.jointCount = in.joints_size();
  std::copy(in.joints().begin(), in.joints().end(), s.joints);
  s.buttons = in.buttons();
  s.deviceTime_s = in.device_time_s();
  return getVec(hand.index(), s.hand.index) && getVec(hand.thumb(), s.hand.thumb) &&
         getVec(hand.wrist(), s.hand.wrist) && getRotation(hand.wrist_rotation(), s.hand.wristRotation) &&
         getVec(hand.middle(), s.hand.extra[0]) && getVec(hand.ring(), s.hand.extra[1]) &&
         getVec(hand.little(), s.hand.extra[2]);
}

// `c` holds the base on entry (zero for raw, raw for sent).
bool getCommand(const hapticgrasp::DeviceCommand& in, device::DeviceCommand& c) {
  if (in.has_f_grasp()) c.f_grasp = in.f_grasp();
  return getChange(in.f_index(), c.f_index) && getChange(in.f_thumb(), c.f_thumb) &&
         getChange(in.f_wrist(), c.f_wrist) && getChange(in.m_wrist(), c.m_wrist) &&
         getChange(in.f_middle(), c.f_extra[0]) && getChange(in.f_ring(), c.f_extra[1]) &&
         getChange(in.f_little(), c.f_extra[2]);
}

bool getMoving(const hapticgrasp::Tick& t, TickRecord& r) {
  // encodeTick lists exactly the first min(count, kMaxMoving) parts.
  if (t.moving_count() < 0 || t.moving_size() != std::min(t.moving_count(), TickRecord::kMaxMoving)) return false;
  r.movingCount = t.moving_count();
  for (int k = 0; k < t.moving_size(); ++k) {
    const hapticgrasp::MovingPart& part = t.moving(k);
    r.movingPart[k] = part.part();
    if (!getRotation(part.rotation(), r.movingPose[k].rotation) || !getVec(part.position(), r.movingPose[k].position))
      return false;
  }
  return true;
}

// The scalars putContact always sets must be there: absent ones are not its form.
bool getContact(const hapticgrasp::Tick& t, contact::ContactReport& c) {
  c = {};
  if (!t.has_contact()) return true;
  const hapticgrasp::Contact& m = t.contact();
  if (!m.has_clearance_m() || !m.has_penetration_m() || !m.has_passivity_energy_j() ||
      !m.has_rotational_passivity_energy_j())
    return false;
  c.part = m.part();
  c.carried = m.carried();
  c.unmodelled = m.unmodelled();
  c.letThrough = m.let_through();
  c.clearance_m = m.clearance_m();
  c.clearanceExact = m.clearance_exact();
  c.otherPart = m.other_part();
  c.heldFace = m.held_face();
  c.otherFace = m.other_face();
  c.penetration_m = m.penetration_m();
  c.contacts = m.contacts();
  c.active = m.active();
  c.substeps = m.substeps();
  c.queried = m.queried();
  c.lagging = m.lagging();
  c.saturated = m.saturated();
  c.passivityEnergy_J = m.passivity_energy_j();
  c.rotationalPassivityEnergy_J = m.rotational_passivity_energy_j();
  return getVec(m.held_point(), c.heldPoint) && getVec(m.other_point(), c.otherPoint) &&
         getVec(m.contact_force_n(), c.contactForce_N) && getVec(m.coupling_force_n(), c.couplingForce_N) &&
         getVec(m.coupling_torque_nm(), c.couplingTorque_Nm);
}

// Enums and narrow integers arrive as wider protobuf types: out of range means not ours.
bool inRange(const hapticgrasp::Tick& t) {
  return t.fingertips() >= 1 && t.fingertips() <= grasp::HandSample::kMaxFingertips &&
         hapticgrasp::GraspState_IsValid(t.state()) && hapticgrasp::GraspState_IsValid(t.state_before()) &&
         t.commands() <= 0xFF && t.watchdog_fault() <= 0xFF;
}

bool getTick(const hapticgrasp::Tick& t, TickRecord& r) {
  if (!inRange(t)) return false;
  r.tick = t.tick();
  r.time_s = t.time_s();
  r.dt_s = t.dt_s();
  r.commands = static_cast<std::uint8_t>(t.commands());
  r.freshSample = t.fresh_sample();
  r.passivityController = t.passivity_controller();
  r.saturated = t.saturated();
  r.stateBefore = static_cast<grasp::GraspState>(t.state_before());
  r.state = static_cast<grasp::GraspState>(t.state());
  r.watchdogFault = static_cast<std::uint8_t>(t.watchdog_fault());
  r.events = t.events();
  r.fingertips = t.fingertips();
  r.graspedPart = t.grasped_part();
  r.watchdogGain = t.has_watchdog_gain() ? t.watchdog_gain() : 1.0;
  r.compute_us = t.compute_us();
  r.deviceIo_us = t.device_io_us();
  r.periodError_us = t.period_error_us();
  r.scenePublications = t.scene_publications();
  if (!getSample(t.sample(), r.sample) || !getCommand(t.raw(), r.raw)) return false;  // r.raw starts at zero
  r.sent = r.raw;
  if (!getCommand(t.sent(), r.sent)) return false;
  return getPorts(t.energy_j(), r.energy_J) && getPorts(t.alpha_ns_per_m(), r.alpha_Ns_per_m) && getMoving(t, r) &&
         getContact(t, r.contact);
}

}  // namespace

void encodeTick(const TickRecord& record, std::string& out) {
  hapticgrasp::Tick* tick = threadArena().freshTick();
  putTick(record, *tick);
  tick->SerializeToString(&out);  // reuses out's capacity
}

bool decodeTick(std::string_view bytes, TickRecord& out) noexcept {
  if (bytes.size() > static_cast<std::size_t>(INT_MAX)) return false;
  try {
    hapticgrasp::Tick* tick = threadArena().freshTick();
    if (!tick->ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) return false;
    TickRecord record;
    if (!getTick(*tick, record)) return false;
    out = record;
    return true;
  } catch (...) {  // only allocation can throw here: refuse the bytes rather than the process
    return false;
  }
}

std::string tickSchema() {
  static const std::string schema = detail::fileDescriptorSet(*hapticgrasp::Tick::descriptor());
  return schema;
}

}  // namespace hg::session
