// The recording's viewable channels: schemas that Foxglove and Lichtblick recognise (exact
// names, the documented field names, numbers and types), hand and part frames, the parts as
// embedded binary STL, the hand as spheres, force arrows and a state label, and log lines.
#include <BRepPrimAPI_MakeBox.hxx>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/dynamic_message.h>
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <map>
#include <memory>
#include <set>

#include "foxglove/FrameTransforms.pb.h"
#include "foxglove/Log.pb.h"
#include "foxglove/SceneUpdate.pb.h"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/geometry/sample_parts.hpp"
#include "hapticgrasp/session/foxglove_messages.hpp"

namespace hg::session {
namespace {

namespace pb = google::protobuf;
using FD = pb::FieldDescriptor;
using servo::TickRecord;

constexpr std::uint64_t kTime_ns = 1'700'000'000'123'456'789ull;

// ---- schemas ----

// A pool built only from a schema's bytes, as a viewer builds it.
struct SchemaPool {
  pb::FileDescriptorSet set;
  pb::DescriptorPool pool;
  std::set<std::string> files;
  explicit SchemaPool(const std::string& schema) {
    EXPECT_TRUE(set.ParseFromString(schema));
    for (const pb::FileDescriptorProto& file : set.file()) {
      EXPECT_NE(pool.BuildFile(file), nullptr) << file.name();  // fails if an import came later
      files.insert(file.name());
    }
  }
};

struct Field {
  const char* message;
  const char* name;
  int number;
  FD::Type type;
  const char* typeName;  // message or enum type, "" for scalars
  bool repeated = false;
};

// Foxglove's documented fields that its 3D and Log panels read.
const Field kFields[] = {
    {"foxglove.FrameTransforms", "transforms", 1, FD::TYPE_MESSAGE, "foxglove.FrameTransform", true},
    {"foxglove.FrameTransform", "timestamp", 1, FD::TYPE_MESSAGE, "google.protobuf.Timestamp"},
    {"foxglove.FrameTransform", "parent_frame_id", 2, FD::TYPE_STRING, ""},
    {"foxglove.FrameTransform", "child_frame_id", 3, FD::TYPE_STRING, ""},
    {"foxglove.FrameTransform", "translation", 4, FD::TYPE_MESSAGE, "foxglove.Vector3"},
    {"foxglove.FrameTransform", "rotation", 5, FD::TYPE_MESSAGE, "foxglove.Quaternion"},
    {"foxglove.Vector3", "x", 1, FD::TYPE_DOUBLE, ""},
    {"foxglove.Vector3", "z", 3, FD::TYPE_DOUBLE, ""},
    {"foxglove.Quaternion", "x", 1, FD::TYPE_DOUBLE, ""},
    {"foxglove.Quaternion", "w", 4, FD::TYPE_DOUBLE, ""},
    {"foxglove.SceneUpdate", "deletions", 1, FD::TYPE_MESSAGE, "foxglove.SceneEntityDeletion", true},
    {"foxglove.SceneUpdate", "entities", 2, FD::TYPE_MESSAGE, "foxglove.SceneEntity", true},
    {"foxglove.SceneEntity", "timestamp", 1, FD::TYPE_MESSAGE, "google.protobuf.Timestamp"},
    {"foxglove.SceneEntity", "frame_id", 2, FD::TYPE_STRING, ""},
    {"foxglove.SceneEntity", "id", 3, FD::TYPE_STRING, ""},
    {"foxglove.SceneEntity", "lifetime", 4, FD::TYPE_MESSAGE, "google.protobuf.Duration"},
    {"foxglove.SceneEntity", "frame_locked", 5, FD::TYPE_BOOL, ""},
    {"foxglove.SceneEntity", "metadata", 6, FD::TYPE_MESSAGE, "foxglove.KeyValuePair", true},
    {"foxglove.SceneEntity", "arrows", 7, FD::TYPE_MESSAGE, "foxglove.ArrowPrimitive", true},
    {"foxglove.SceneEntity", "cubes", 8, FD::TYPE_MESSAGE, "foxglove.CubePrimitive", true},
    {"foxglove.SceneEntity", "spheres", 9, FD::TYPE_MESSAGE, "foxglove.SpherePrimitive", true},
    {"foxglove.SceneEntity", "cylinders", 10, FD::TYPE_MESSAGE, "foxglove.CylinderPrimitive", true},
    {"foxglove.SceneEntity", "lines", 11, FD::TYPE_MESSAGE, "foxglove.LinePrimitive", true},
    {"foxglove.SceneEntity", "triangles", 12, FD::TYPE_MESSAGE, "foxglove.TriangleListPrimitive", true},
    {"foxglove.SceneEntity", "texts", 13, FD::TYPE_MESSAGE, "foxglove.TextPrimitive", true},
    {"foxglove.SceneEntity", "models", 14, FD::TYPE_MESSAGE, "foxglove.ModelPrimitive", true},
    {"foxglove.ModelPrimitive", "pose", 1, FD::TYPE_MESSAGE, "foxglove.Pose"},
    {"foxglove.ModelPrimitive", "scale", 2, FD::TYPE_MESSAGE, "foxglove.Vector3"},
    {"foxglove.ModelPrimitive", "color", 3, FD::TYPE_MESSAGE, "foxglove.Color"},
    {"foxglove.ModelPrimitive", "override_color", 4, FD::TYPE_BOOL, ""},
    {"foxglove.ModelPrimitive", "url", 5, FD::TYPE_STRING, ""},
    {"foxglove.ModelPrimitive", "media_type", 6, FD::TYPE_STRING, ""},
    {"foxglove.ModelPrimitive", "data", 7, FD::TYPE_BYTES, ""},
    {"foxglove.SpherePrimitive", "pose", 1, FD::TYPE_MESSAGE, "foxglove.Pose"},
    {"foxglove.SpherePrimitive", "size", 2, FD::TYPE_MESSAGE, "foxglove.Vector3"},
    {"foxglove.SpherePrimitive", "color", 3, FD::TYPE_MESSAGE, "foxglove.Color"},
    {"foxglove.ArrowPrimitive", "pose", 1, FD::TYPE_MESSAGE, "foxglove.Pose"},
    {"foxglove.ArrowPrimitive", "shaft_length", 2, FD::TYPE_DOUBLE, ""},
    {"foxglove.ArrowPrimitive", "shaft_diameter", 3, FD::TYPE_DOUBLE, ""},
    {"foxglove.ArrowPrimitive", "head_length", 4, FD::TYPE_DOUBLE, ""},
    {"foxglove.ArrowPrimitive", "head_diameter", 5, FD::TYPE_DOUBLE, ""},
    {"foxglove.ArrowPrimitive", "color", 6, FD::TYPE_MESSAGE, "foxglove.Color"},
    {"foxglove.TextPrimitive", "pose", 1, FD::TYPE_MESSAGE, "foxglove.Pose"},
    {"foxglove.TextPrimitive", "billboard", 2, FD::TYPE_BOOL, ""},
    {"foxglove.TextPrimitive", "font_size", 3, FD::TYPE_DOUBLE, ""},
    {"foxglove.TextPrimitive", "scale_invariant", 4, FD::TYPE_BOOL, ""},
    {"foxglove.TextPrimitive", "color", 5, FD::TYPE_MESSAGE, "foxglove.Color"},
    {"foxglove.TextPrimitive", "text", 6, FD::TYPE_STRING, ""},
    {"foxglove.Pose", "position", 1, FD::TYPE_MESSAGE, "foxglove.Vector3"},
    {"foxglove.Pose", "orientation", 2, FD::TYPE_MESSAGE, "foxglove.Quaternion"},
    {"foxglove.Color", "r", 1, FD::TYPE_DOUBLE, ""},
    {"foxglove.Color", "a", 4, FD::TYPE_DOUBLE, ""},
    {"foxglove.Log", "timestamp", 1, FD::TYPE_MESSAGE, "google.protobuf.Timestamp"},
    {"foxglove.Log", "level", 2, FD::TYPE_ENUM, "foxglove.Log.Level"},
    {"foxglove.Log", "message", 3, FD::TYPE_STRING, ""},
    {"foxglove.Log", "name", 4, FD::TYPE_STRING, ""},
    {"foxglove.Log", "file", 5, FD::TYPE_STRING, ""},
    {"foxglove.Log", "line", 6, FD::TYPE_FIXED32, ""},
};

void expectFields(const SchemaPool& schema, std::string_view root) {
  for (const Field& f : kFields) {
    const pb::Descriptor* message = schema.pool.FindMessageTypeByName(f.message);
    if (!message) continue;  // in another schema's set
    SCOPED_TRACE(std::string(root) + ": " + f.message + "." + f.name);
    const FD* field = message->FindFieldByName(f.name);
    ASSERT_NE(field, nullptr);
    EXPECT_EQ(field->number(), f.number);
    EXPECT_EQ(field->type(), f.type);
    EXPECT_EQ(field->is_repeated(), f.repeated);
    const std::string typeName = f.type == FD::TYPE_MESSAGE ? field->message_type()->full_name()
                                 : f.type == FD::TYPE_ENUM  ? field->enum_type()->full_name()
                                                            : "";
    EXPECT_EQ(typeName, f.typeName);
  }
}

TEST(FoxgloveMessages, SchemasCarryFoxglovesNamesAndFields) {
  const SchemaPool frames(frameTransformsSchema()), scene(sceneUpdateSchema()), log(logSchema());
  EXPECT_EQ(kFrameTransformsSchemaName, "foxglove.FrameTransforms");
  EXPECT_EQ(kSceneUpdateSchemaName, "foxglove.SceneUpdate");
  EXPECT_EQ(kLogSchemaName, "foxglove.Log");
  ASSERT_NE(frames.pool.FindMessageTypeByName(std::string(kFrameTransformsSchemaName)), nullptr);
  ASSERT_NE(scene.pool.FindMessageTypeByName(std::string(kSceneUpdateSchemaName)), nullptr);
  ASSERT_NE(log.pool.FindMessageTypeByName(std::string(kLogSchemaName)), nullptr);
  // Each schema stands alone: the well-known types it uses travel with it.
  EXPECT_TRUE(frames.files.count("google/protobuf/timestamp.proto"));
  EXPECT_TRUE(scene.files.count("google/protobuf/timestamp.proto"));
  EXPECT_TRUE(scene.files.count("google/protobuf/duration.proto"));
  EXPECT_TRUE(log.files.count("google/protobuf/timestamp.proto"));
  EXPECT_FALSE(log.files.count("foxglove/SceneEntity.proto"));  // only what Log needs
  expectFields(frames, "FrameTransforms");
  expectFields(scene, "SceneUpdate");
  expectFields(log, "Log");
  const pb::EnumDescriptor* level = log.pool.FindEnumTypeByName("foxglove.Log.Level");
  ASSERT_NE(level, nullptr);
  EXPECT_EQ(level->FindValueByName("DEBUG")->number(), 1);
  EXPECT_EQ(level->FindValueByName("FATAL")->number(), 5);
}

// ---- hand and part frames ----

TickRecord handRecord() {
  TickRecord r;
  r.fingertips = 3;
  r.sample.hand.index = Vec3(0.10, 0.02, 0.30);
  r.sample.hand.thumb = Vec3(0.09, -0.03, 0.29);
  r.sample.hand.extra[0] = Vec3(0.11, 0.04, 0.31);
  r.sample.hand.extra[1] = Vec3(5, 5, 5);  // a fingertip this hand does not use: no frame
  r.sample.hand.wrist = Vec3(0.02, 0.0, 0.35);
  r.sample.hand.wristRotation = Eigen::AngleAxisd(2.5, Vec3(0.3, -0.4, 1).normalized()).toRotationMatrix();
  r.movingCount = 2;
  r.movingPart[0] = 2;
  r.movingPose[0].rotation = Eigen::AngleAxisd(-1.2, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  r.movingPose[0].position = Vec3(0.1, 0.2, 0.3);
  r.movingPart[1] = 0;
  r.movingPose[1].position = Vec3(-0.1, 0, 0);
  r.sent.f_index = Vec3(0, 0, -2);
  r.sent.f_thumb = Vec3(1, 1, 0);
  r.sent.f_wrist = Vec3(0, 0, 4.9);
  return r;
}
const std::vector<std::string> kPartNames = {"cylinder", "block", "loft"};

Mat3 matrix(const foxglove::Quaternion& q) { return Quat(q.w(), q.x(), q.y(), q.z()).toRotationMatrix(); }
Vec3 vec(const foxglove::Vector3& v) { return Vec3(v.x(), v.y(), v.z()); }

std::map<std::string, const foxglove::FrameTransform*> byChild(const foxglove::FrameTransforms& msg) {
  std::map<std::string, const foxglove::FrameTransform*> out;
  for (const foxglove::FrameTransform& t : msg.transforms()) out[t.child_frame_id()] = &t;
  return out;
}

TEST(FoxgloveMessages, HandFramesHoldFingertipsInUseTheWristAndMovingParts) {
  const TickRecord r = handRecord();
  std::string bytes;
  encodeHandFrames(r, kPartNames, kTime_ns, bytes);
  foxglove::FrameTransforms msg;
  ASSERT_TRUE(msg.ParseFromString(bytes));
  EXPECT_EQ(msg.transforms_size(), 3 + 1 + 2);
  const auto frames = byChild(msg);
  for (const char* name : {"fingertip/index", "fingertip/thumb", "fingertip/middle", "wrist", "part/loft",
                           "part/cylinder"})
    EXPECT_TRUE(frames.count(name)) << name;
  EXPECT_FALSE(frames.count("fingertip/ring"));
  for (const foxglove::FrameTransform& t : msg.transforms()) {
    EXPECT_EQ(t.parent_frame_id(), "world");
    EXPECT_EQ(t.timestamp().seconds(), 1'700'000'000);
    EXPECT_EQ(t.timestamp().nanos(), 123'456'789);
    const foxglove::Quaternion& q = t.rotation();
    EXPECT_NEAR(q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w(), 1.0, 1e-12) << t.child_frame_id();
  }
  EXPECT_TRUE(vec(frames.at("fingertip/middle")->translation()).isApprox(r.sample.hand.extra[0]));
  const foxglove::FrameTransform& wrist = *frames.at("wrist");
  EXPECT_TRUE(vec(wrist.translation()).isApprox(r.sample.hand.wrist));
  EXPECT_TRUE(matrix(wrist.rotation()).isApprox(r.sample.hand.wristRotation, 1e-12));
  const foxglove::FrameTransform& loft = *frames.at("part/loft");
  EXPECT_TRUE(vec(loft.translation()).isApprox(r.movingPose[0].position));
  EXPECT_TRUE(matrix(loft.rotation()).isApprox(r.movingPose[0].rotation, 1e-12));
  EXPECT_TRUE(matrix(frames.at("part/cylinder")->rotation()).isIdentity(1e-15));
}

TEST(FoxgloveMessages, HandFramesLeaveOutWhatIsNotFinite) {
  TickRecord r = handRecord();
  r.sample.hand.thumb.y() = std::numeric_limits<double>::quiet_NaN();
  r.sample.hand.wristRotation(0, 0) = std::numeric_limits<double>::infinity();
  std::string bytes;
  encodeHandFrames(r, kPartNames, kTime_ns, bytes);
  foxglove::FrameTransforms msg;
  ASSERT_TRUE(msg.ParseFromString(bytes));
  const auto frames = byChild(msg);
  EXPECT_EQ(msg.transforms_size(), 4);
  EXPECT_FALSE(frames.count("fingertip/thumb"));
  EXPECT_FALSE(frames.count("wrist"));
}

TEST(FoxgloveMessages, PartFramesNameEveryPart) {
  std::vector<grasp::PartPose> poses(3);
  poses[1].position = Vec3(0.5, 0, 0);
  poses[2].rotation = Eigen::AngleAxisd(0.7, Vec3::UnitZ()).toRotationMatrix();
  std::string bytes;
  encodePartFrames(poses, kPartNames, kTime_ns, bytes);
  foxglove::FrameTransforms msg;
  ASSERT_TRUE(msg.ParseFromString(bytes));
  ASSERT_EQ(msg.transforms_size(), 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(msg.transforms(k).child_frame_id(), "part/" + kPartNames[k]);
    EXPECT_TRUE(vec(msg.transforms(k).translation()).isApprox(poses[k].position));
    EXPECT_TRUE(matrix(msg.transforms(k).rotation()).isApprox(poses[k].rotation, 1e-12));
  }
}

// ---- parts as embedded STL ----

std::uint32_t u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(s[at + k]);
  return v;
}
float f32(const std::string& s, std::size_t at) { return std::bit_cast<float>(u32(s, at)); }

// The one model of a one-part SceneUpdate, with the entity checked.
foxglove::ModelPrimitive partModel(const PartMesh& mesh) {
  std::string bytes;
  encodePartModels(std::span(&mesh, 1), kTime_ns, bytes);
  foxglove::SceneUpdate msg;
  EXPECT_TRUE(msg.ParseFromString(bytes));
  EXPECT_EQ(msg.entities_size(), 1);
  const foxglove::SceneEntity& e = msg.entities(0);
  EXPECT_EQ(e.id(), "part/" + mesh.name);
  EXPECT_EQ(e.frame_id(), "part/" + mesh.name);
  EXPECT_TRUE(e.frame_locked());
  EXPECT_EQ(e.models_size(), 1);
  const foxglove::ModelPrimitive& m = e.models(0);
  EXPECT_EQ(m.media_type(), "model/stl");
  EXPECT_GT(m.color().a(), 0);
  EXPECT_EQ(vec(m.scale()), Vec3::Ones());
  EXPECT_EQ(m.pose().orientation().w(), 1);
  return m;
}

void expectValidStl(const std::string& stl, std::size_t triangles) {
  ASSERT_GE(stl.size(), 84u);
  EXPECT_NE(stl.substr(0, 5), "solid");  // readers would take it for ASCII STL
  EXPECT_EQ(u32(stl, 80), triangles);
  EXPECT_EQ(stl.size(), 84 + 50 * triangles);
}

TEST(FoxgloveMessages, BoxMeshIsABinaryStlInMetresWithOutwardNormals) {
  const geometry::PartModelPtr box = geometry::PartModel::fromShape(BRepPrimAPI_MakeBox(100, 60, 30).Shape(),
                                                                    geometry::LengthUnit::Millimetre, "box");
  const PartMesh mesh = partMesh(*box, "box", 0.001);
  EXPECT_EQ(mesh.triangles.size(), 3u * 12);  // two triangles a face
  const std::string stl = partModel(mesh).data();
  expectValidStl(stl, 12);
  const Vec3 centre(0.05, 0.03, 0.015);
  for (std::size_t t = 0; t < 12; ++t) {
    const std::size_t at = 84 + 50 * t;
    const Vec3 n(f32(stl, at), f32(stl, at + 4), f32(stl, at + 8));
    Vec3 mid = Vec3::Zero();
    for (int v = 0; v < 3; ++v) {
      const Vec3 p(f32(stl, at + 12 + 12 * v), f32(stl, at + 16 + 12 * v), f32(stl, at + 20 + 12 * v));
      EXPECT_TRUE((p.array() >= -1e-6).all() && (p.array() <= Vec3(0.1, 0.06, 0.03).array() + 1e-6).all()) << p;
      mid += p / 3;
    }
    EXPECT_NEAR(n.norm(), 1.0, 1e-6) << t;
    EXPECT_GT(n.dot(mid - centre), 0) << "triangle " << t << " faces inwards";
  }
}

TEST(FoxgloveMessages, SamplePartMeshMatchesItsTriangleCount) {
  const geometry::SamplePart block = geometry::findPart("block");
  const geometry::PartModelPtr part = geometry::PartModel::fromFile(block.file, block.unit);
  const PartMesh mesh = partMesh(*part, "block", 0.0005);
  ASSERT_GT(mesh.triangles.size(), 3u * 58);  // at least one a face
  expectValidStl(partModel(mesh).data(), mesh.triangles.size() / 3);
}

// ---- the hand scene ----

TEST(FoxgloveMessages, HandSceneDrawsFingertipsForcesAndState) {
  const TickRecord r = handRecord();
  std::string bytes;
  encodeHandScene(r, "GRASP", kTime_ns, bytes);
  foxglove::SceneUpdate msg;
  ASSERT_TRUE(msg.ParseFromString(bytes));
  ASSERT_EQ(msg.entities_size(), 3);
  const foxglove::SceneEntity &tips = msg.entities(0), &forces = msg.entities(1), &state = msg.entities(2);
  EXPECT_EQ(tips.id(), "hand/fingertips");
  EXPECT_EQ(forces.id(), "hand/forces");
  EXPECT_EQ(state.id(), "hand/state");
  for (const foxglove::SceneEntity& e : msg.entities()) {
    EXPECT_EQ(e.frame_id(), "world");
    EXPECT_EQ(e.timestamp().seconds(), 1'700'000'000);
  }
  ASSERT_EQ(tips.spheres_size(), 3);
  EXPECT_TRUE(vec(tips.spheres(2).pose().position()).isApprox(r.sample.hand.extra[0]));
  EXPECT_DOUBLE_EQ(tips.spheres(0).size().x(), kFingertipDiameter_m);
  // Index, thumb and wrist push; the middle finger's force is zero and draws nothing.
  ASSERT_EQ(forces.arrows_size(), 3);
  const Vec3 tails[] = {r.sample.hand.index, r.sample.hand.thumb, r.sample.hand.wrist};
  const Vec3 pushes[] = {r.sent.f_index, r.sent.f_thumb, r.sent.f_wrist};
  for (int k = 0; k < 3; ++k) {
    const foxglove::ArrowPrimitive& a = forces.arrows(k);
    EXPECT_TRUE(vec(a.pose().position()).isApprox(tails[k])) << k;
    const Vec3 along = matrix(a.pose().orientation()) * Vec3::UnitX();
    EXPECT_TRUE(along.isApprox(pushes[k].normalized(), 1e-12)) << k << ": " << along.transpose();
    EXPECT_NEAR(a.shaft_length() + a.head_length(), pushes[k].norm() * kArrowLength_m_per_N, 1e-12) << k;
  }
  ASSERT_EQ(state.texts_size(), 1);
  EXPECT_EQ(state.texts(0).text(), "GRASP");
  EXPECT_GT(state.texts(0).pose().position().z(), r.sample.hand.wrist.z());
}

TEST(FoxgloveMessages, HandSceneKeepsItsEntityIds) {
  // Stable ids: each update replaces the last in the viewer instead of piling up.
  TickRecord r = handRecord();
  std::string first, second;
  encodeHandScene(r, "GRASP", kTime_ns, first);
  r.fingertips = 2;
  r.sent = device::DeviceCommand{};
  encodeHandScene(r, "FREE", kTime_ns + 1000, second);
  foxglove::SceneUpdate a, b;
  ASSERT_TRUE(a.ParseFromString(first) && b.ParseFromString(second));
  ASSERT_EQ(a.entities_size(), b.entities_size());
  for (int k = 0; k < a.entities_size(); ++k) EXPECT_EQ(a.entities(k).id(), b.entities(k).id());
  EXPECT_EQ(b.entities(1).arrows_size(), 0);  // no force, no arrow
  EXPECT_EQ(b.entities(0).spheres_size(), 2);
}

// ---- log ----

TEST(FoxgloveMessages, LogLinesCarryLevelNameAndTime) {
  std::string bytes;
  encodeLog(kTime_ns, kLogWarning, "reviewer", "index slips at 12.3 s", bytes);
  foxglove::Log log;
  ASSERT_TRUE(log.ParseFromString(bytes));
  EXPECT_EQ(log.level(), foxglove::Log::WARNING);
  EXPECT_EQ(log.name(), "reviewer");
  EXPECT_EQ(log.message(), "index slips at 12.3 s");
  EXPECT_EQ(log.timestamp().seconds(), 1'700'000'000);
  EXPECT_EQ(log.timestamp().nanos(), 123'456'789);
  encodeLog(kTime_ns, 17, "grasp", "lift", bytes);
  ASSERT_TRUE(log.ParseFromString(bytes));
  EXPECT_EQ(log.level(), foxglove::Log::UNKNOWN);
}

TEST(FoxgloveMessages, SchemasDecodeTheMessagesWithNothingUnknown) {
  // What a viewer holds after decoding by the schema in the file: every field known.
  std::string frames, scene, log;
  encodeHandFrames(handRecord(), kPartNames, kTime_ns, frames);
  encodeHandScene(handRecord(), "MANIPULATE", kTime_ns, scene);
  encodeLog(kTime_ns, kLogInfo, "grasp", "lift", log);
  const std::pair<std::string, const std::string*> cases[] = {
      {frameTransformsSchema(), &frames}, {sceneUpdateSchema(), &scene}, {logSchema(), &log}};
  const std::string_view names[] = {kFrameTransformsSchemaName, kSceneUpdateSchemaName, kLogSchemaName};
  for (int k = 0; k < 3; ++k) {
    const SchemaPool schema(cases[k].first);
    const pb::Descriptor* type = schema.pool.FindMessageTypeByName(std::string(names[k]));
    ASSERT_NE(type, nullptr);
    pb::DynamicMessageFactory factory(&schema.pool);
    std::unique_ptr<pb::Message> msg(factory.GetPrototype(type)->New());
    ASSERT_TRUE(msg->ParseFromString(*cases[k].second)) << names[k];
    EXPECT_TRUE(msg->GetReflection()->GetUnknownFields(*msg).empty()) << names[k];
    EXPECT_EQ(msg->SerializeAsString(), *cases[k].second) << names[k];
  }
}

}  // namespace
}  // namespace hg::session
