#include "hapticgrasp/session/foxglove_messages.hpp"

#include <algorithm>
#include <cmath>

#include "binary_stl.hpp"
#include "descriptor_set.hpp"
#include "foxglove/FrameTransforms.pb.h"
#include "foxglove/Log.pb.h"
#include "foxglove/SceneUpdate.pb.h"
#include "hapticgrasp/geometry/tessellation.hpp"

namespace hg::session {
namespace {

namespace fg = ::foxglove;

constexpr const char* kFingerNames[grasp::HandSample::kMaxFingertips] = {"index", "thumb", "middle", "ring",
                                                                         "little"};

struct Rgba {
  double r, g, b, a;
};
constexpr Rgba kFingerColours[grasp::HandSample::kMaxFingertips] = {
    {0.20, 0.60, 1.00, 1}, {1.00, 0.55, 0.10, 1}, {0.30, 0.85, 0.35, 1}, {0.80, 0.35, 0.90, 1}, {0.95, 0.85, 0.20, 1}};
constexpr Rgba kForceColour{0.90, 0.15, 0.15, 1};
constexpr Rgba kWristForceColour{0.95, 0.45, 0.45, 1};
constexpr Rgba kTextColour{1, 1, 1, 1};
// Parts cycle through muted colours, slightly translucent so fingertips inside stay visible.
constexpr Rgba kPartColours[] = {{0.62, 0.66, 0.72, 0.85}, {0.72, 0.62, 0.52, 0.85}, {0.55, 0.70, 0.60, 0.85},
                                 {0.70, 0.58, 0.70, 0.85}, {0.58, 0.66, 0.78, 0.85}, {0.76, 0.72, 0.55, 0.85}};

constexpr double kArrowShaftDiameter_m = 0.0015;
constexpr double kArrowHeadDiameter_m = 0.004;
constexpr double kArrowMaxHead_m = 0.006;
constexpr double kSmallestForce_N = 1e-6;  // below this an arrow has no direction worth drawing
constexpr double kStateTextAbove_m = 0.04;
constexpr double kStateFontSize_px = 14;

void setTime(std::uint64_t ns, google::protobuf::Timestamp* t) {
  t->set_seconds(static_cast<std::int64_t>(ns / 1'000'000'000u));
  t->set_nanos(static_cast<std::int32_t>(ns % 1'000'000'000u));
}
void setVec(const Vec3& v, fg::Vector3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}
void setQuat(const Quat& q, fg::Quaternion* out) {
  out->set_x(q.x());
  out->set_y(q.y());
  out->set_z(q.z());
  out->set_w(q.w());
}
void setColour(const Rgba& c, fg::Color* out) {
  out->set_r(c.r);
  out->set_g(c.g);
  out->set_b(c.b);
  out->set_a(c.a);
}
void setPose(const Vec3& position, const Quat& orientation, fg::Pose* out) {
  setVec(position, out->mutable_position());
  setQuat(orientation, out->mutable_orientation());
}

// The unit quaternion of a rotation matrix; false when the matrix gives none (not finite,
// or so far from a rotation that the extraction fails).
bool unitQuat(const Mat3& m, Quat& q) {
  if (!m.allFinite()) return false;
  q = Quat(m);
  const double norm = q.norm();
  if (!std::isfinite(norm) || norm < 1e-9) return false;
  q.coeffs() /= norm;
  return true;
}

void addTransform(std::string_view child, const Vec3& position, const Quat& rotation, std::uint64_t ns,
                  fg::FrameTransforms& msg) {
  fg::FrameTransform* t = msg.add_transforms();
  setTime(ns, t->mutable_timestamp());
  t->set_parent_frame_id(std::string(kWorldFrame));
  t->set_child_frame_id(std::string(child));
  setVec(position, t->mutable_translation());
  setQuat(rotation, t->mutable_rotation());
}

void addPartTransform(std::string_view name, const grasp::PartPose& pose, std::uint64_t ns,
                      fg::FrameTransforms& msg) {
  Quat q;
  if (pose.position.allFinite() && unitQuat(pose.rotation, q)) addTransform(partFrame(name), pose.position, q, ns, msg);
}

int fingertipsInUse(const servo::TickRecord& r) {
  return std::clamp(r.fingertips, 0, grasp::HandSample::kMaxFingertips);
}

fg::SceneEntity* addEntity(std::string_view id, std::string_view frame, bool frameLocked, std::uint64_t ns,
                           fg::SceneUpdate& msg) {
  fg::SceneEntity* e = msg.add_entities();
  setTime(ns, e->mutable_timestamp());
  e->set_id(std::string(id));
  e->set_frame_id(std::string(frame));
  e->set_frame_locked(frameLocked);
  return e;
}

// An arrow from `tail` along `force`, as long as kArrowLength_m_per_N says.
void addForceArrow(const Vec3& tail, const Vec3& force, const Rgba& colour, fg::SceneEntity& e) {
  const double magnitude = force.norm();
  if (!tail.allFinite() || !std::isfinite(magnitude) || magnitude < kSmallestForce_N) return;
  const double length = magnitude * kArrowLength_m_per_N;
  const double head = std::min(0.3 * length, kArrowMaxHead_m);
  fg::ArrowPrimitive* a = e.add_arrows();
  setPose(tail, Quat::FromTwoVectors(Vec3::UnitX(), force), a->mutable_pose());  // arrows point along +x
  a->set_shaft_length(length - head);
  a->set_shaft_diameter(kArrowShaftDiameter_m);
  a->set_head_length(head);
  a->set_head_diameter(kArrowHeadDiameter_m);
  setColour(colour, a->mutable_color());
}

void addFingertips(const servo::TickRecord& r, std::uint64_t ns, fg::SceneUpdate& msg) {
  fg::SceneEntity* e = addEntity("hand/fingertips", kWorldFrame, false, ns, msg);
  for (int k = 0; k < fingertipsInUse(r); ++k) {
    const Vec3& p = r.sample.hand.fingertip(k);
    if (!p.allFinite()) continue;
    fg::SpherePrimitive* s = e->add_spheres();
    setPose(p, Quat::Identity(), s->mutable_pose());
    setVec(Vec3::Constant(kFingertipDiameter_m), s->mutable_size());
    setColour(kFingerColours[k], s->mutable_color());
  }
}

void addForces(const servo::TickRecord& r, std::uint64_t ns, fg::SceneUpdate& msg) {
  fg::SceneEntity* e = addEntity("hand/forces", kWorldFrame, false, ns, msg);
  for (int k = 0; k < fingertipsInUse(r); ++k)
    addForceArrow(r.sample.hand.fingertip(k), r.sent.fingertipForce(k), kForceColour, *e);
  addForceArrow(r.sample.hand.wrist, r.sent.f_wrist, kWristForceColour, *e);
}

void addStateText(const servo::TickRecord& r, std::string_view stateName, std::uint64_t ns, fg::SceneUpdate& msg) {
  fg::SceneEntity* e = addEntity("hand/state", kWorldFrame, false, ns, msg);
  const Vec3& wrist = r.sample.hand.wrist;
  fg::TextPrimitive* t = e->add_texts();
  setPose((wrist.allFinite() ? wrist : Vec3::Zero()) + kStateTextAbove_m * Vec3::UnitZ(), Quat::Identity(),
          t->mutable_pose());
  t->set_billboard(true);
  t->set_font_size(kStateFontSize_px);
  t->set_scale_invariant(true);  // readable at any zoom
  setColour(kTextColour, t->mutable_color());
  t->set_text(std::string(stateName));
}

void addPartModel(const PartMesh& mesh, std::size_t k, std::uint64_t ns, fg::SceneUpdate& msg) {
  const std::string frame = partFrame(mesh.name);
  fg::SceneEntity* e = addEntity(frame, frame, true, ns, msg);
  fg::ModelPrimitive* m = e->add_models();
  setPose(Vec3::Zero(), Quat::Identity(), m->mutable_pose());  // the mesh is in the part frame
  setVec(Vec3::Ones(), m->mutable_scale());
  setColour(kPartColours[k % std::size(kPartColours)], m->mutable_color());
  m->set_override_color(true);  // STL has no material of its own
  m->set_media_type("model/stl");
  m->set_data(detail::binaryStl(mesh.vertices, mesh.triangles, mesh.name));
}

}  // namespace

std::string frameTransformsSchema() {
  static const std::string schema = detail::fileDescriptorSet(*fg::FrameTransforms::descriptor());
  return schema;
}
std::string sceneUpdateSchema() {
  static const std::string schema = detail::fileDescriptorSet(*fg::SceneUpdate::descriptor());
  return schema;
}
std::string logSchema() {
  static const std::string schema = detail::fileDescriptorSet(*fg::Log::descriptor());
  return schema;
}

std::string fingertipFrame(int k) {
  const bool known = k >= 0 && k < grasp::HandSample::kMaxFingertips;
  return std::string("fingertip/") + (known ? kFingerNames[k] : std::to_string(k).c_str());
}
std::string partFrame(std::string_view name) { return "part/" + std::string(name); }

void encodeHandFrames(const servo::TickRecord& r, std::span<const std::string> partNames, std::uint64_t time_ns,
                      std::string& out) {
  fg::FrameTransforms msg;
  const grasp::HandSample& hand = r.sample.hand;
  for (int k = 0; k < fingertipsInUse(r); ++k)
    if (hand.fingertip(k).allFinite()) addTransform(fingertipFrame(k), hand.fingertip(k), Quat::Identity(), time_ns, msg);
  Quat wristRotation;
  if (hand.wrist.allFinite() && unitQuat(hand.wristRotation, wristRotation))
    addTransform(kWristFrame, hand.wrist, wristRotation, time_ns, msg);
  const int moving = std::clamp(r.movingCount, 0, servo::TickRecord::kMaxMoving);
  for (int k = 0; k < moving; ++k) {
    const int part = r.movingPart[k];
    // A part the caller has no name for keeps its index, rather than vanishing from view.
    const bool named = part >= 0 && static_cast<std::size_t>(part) < partNames.size();
    addPartTransform(named ? partNames[part] : std::to_string(part), r.movingPose[k], time_ns, msg);
  }
  msg.SerializeToString(&out);
}

void encodePartFrames(std::span<const grasp::PartPose> poses, std::span<const std::string> names,
                      std::uint64_t time_ns, std::string& out) {
  fg::FrameTransforms msg;
  for (std::size_t k = 0; k < std::min(poses.size(), names.size()); ++k)
    addPartTransform(names[k], poses[k], time_ns, msg);
  msg.SerializeToString(&out);
}

PartMesh partMesh(const geometry::PartModel& part, std::string name, double deflection_m) {
  const geometry::Tessellation mesh = geometry::tessellate(part, deflection_m);
  PartMesh out{std::move(name), {}, {}};
  out.vertices.reserve(3 * mesh.vertices.size());
  for (const Vec3& v : mesh.vertices)
    for (int k = 0; k < 3; ++k) out.vertices.push_back(static_cast<float>(v[k]));
  out.triangles.reserve(3 * mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) out.triangles.push_back(static_cast<std::uint32_t>(t[k]));
  return out;
}

void encodePartModels(std::span<const PartMesh> meshes, std::uint64_t time_ns, std::string& out) {
  fg::SceneUpdate msg;
  for (std::size_t k = 0; k < meshes.size(); ++k) addPartModel(meshes[k], k, time_ns, msg);
  msg.SerializeToString(&out);
}

void encodeHandScene(const servo::TickRecord& record, std::string_view stateName, std::uint64_t time_ns,
                     std::string& out) {
  fg::SceneUpdate msg;
  addFingertips(record, time_ns, msg);
  addForces(record, time_ns, msg);
  addStateText(record, stateName, time_ns, msg);
  msg.SerializeToString(&out);
}

void encodeLog(std::uint64_t time_ns, int level, std::string_view name, std::string_view message, std::string& out) {
  fg::Log msg;
  setTime(time_ns, msg.mutable_timestamp());
  msg.set_level(fg::Log::Level_IsValid(level) ? static_cast<fg::Log::Level>(level) : fg::Log::UNKNOWN);
  msg.set_name(std::string(name));
  msg.set_message(std::string(message));
  msg.SerializeToString(&out);
}

bool decodeLog(std::string_view bytes, LogEntry& out) {
  fg::Log msg;
  if (!msg.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) return false;
  out.time_ns = static_cast<std::uint64_t>(msg.timestamp().seconds()) * 1'000'000'000u +
                static_cast<std::uint64_t>(msg.timestamp().nanos());
  out.level = msg.level();
  out.name = msg.name();
  out.message = msg.message();
  return true;
}

PartMesh boxMesh(const geometry::Aabb& box, std::string name) {
  PartMesh mesh;
  mesh.name = std::move(name);
  if (box.empty()) return mesh;
  for (int i = 0; i < 8; ++i) {  // corner i: bit 0 x, bit 1 y, bit 2 z
    mesh.vertices.push_back(static_cast<float>(i & 1 ? box.max.x() : box.min.x()));
    mesh.vertices.push_back(static_cast<float>(i & 2 ? box.max.y() : box.min.y()));
    mesh.vertices.push_back(static_cast<float>(i & 4 ? box.max.z() : box.min.z()));
  }
  // Two outward-wound triangles per face.
  mesh.triangles = {0, 2, 3, 0, 3, 1,  4, 5, 7, 4, 7, 6,  0, 1, 5, 0, 5, 4,
                    2, 6, 7, 2, 7, 3,  0, 4, 6, 0, 6, 2,  1, 3, 7, 1, 7, 5};
  return mesh;
}

}  // namespace hg::session
