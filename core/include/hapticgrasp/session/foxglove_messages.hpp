#pragma once
// The recording's viewable channels: messages in Foxglove's well-known protobuf schemas
// (core/proto/foxglove), so that Foxglove or Lichtblick open a session as a 3D scene with
// the hand, its forces and the parts, and a log of events and notes.
//
// Frames: "world" is the root (the absolute frame, metres); each part is "part/<name>", each
// fingertip "fingertip/<index|thumb|middle|ring|little>", the wrist "wrist". Every encoder
// overwrites `out` with one message; time_ns is the message's time (one clock for the whole
// recording: a zero time beside real ones breaks the viewer's time range).
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/servo/tick_record.hpp"

namespace hg::geometry {
class PartModel;
}

namespace hg::session {

// Schema names (MCAP schema encoding "protobuf") and their FileDescriptorSets, which include
// google/protobuf/timestamp.proto and duration.proto where the messages use them.
inline constexpr std::string_view kFrameTransformsSchemaName = "foxglove.FrameTransforms";
inline constexpr std::string_view kSceneUpdateSchemaName = "foxglove.SceneUpdate";
inline constexpr std::string_view kLogSchemaName = "foxglove.Log";
std::string frameTransformsSchema();
std::string sceneUpdateSchema();
std::string logSchema();

inline constexpr std::string_view kWorldFrame = "world";
inline constexpr std::string_view kWristFrame = "wrist";
std::string fingertipFrame(int k);  // k as HandSample::fingertip(k): 0 index, 1 thumb, ...
std::string partFrame(std::string_view name);

// FrameTransforms from world to each fingertip in use (record.fingertips), to the wrist
// (rotated by wristRotation), and to each moving part, named by its index in partNames. A
// frame whose pose is not finite (a device fault the watchdog caught) is left out.
void encodeHandFrames(const servo::TickRecord& record, std::span<const std::string> partNames, std::uint64_t time_ns,
                      std::string& out);

// FrameTransforms from world to every part: poses[k] is where names[k] is.
void encodePartFrames(std::span<const grasp::PartPose> poses, std::span<const std::string> names,
                      std::uint64_t time_ns, std::string& out);

// A part's surface as triangles, for the viewer.
struct PartMesh {
  std::string name;
  std::vector<float> vertices;              // x, y, z per vertex; metres, part frame
  std::vector<std::uint32_t> triangles;     // three vertex indices per triangle, outward CCW
};
PartMesh partMesh(const geometry::PartModel& part, std::string name, double deflection_m);

// One SceneUpdate with an entity per part ("part/<name>"), frame-locked to the part's frame:
// a ModelPrimitive holding the mesh as binary STL ("model/stl") and a colour. Written once;
// the part frames move the models afterwards.
void encodePartModels(std::span<const PartMesh> meshes, std::uint64_t time_ns, std::string& out);

// The hand as a SceneUpdate in the world frame, entities "hand/fingertips" (8 mm spheres),
// "hand/forces" (the sent forces as arrows at the fingertips and the wrist, 10 mm per N)
// and "hand/state" (stateName as text above the wrist). Each update replaces the last.
inline constexpr double kFingertipDiameter_m = 0.008;
inline constexpr double kArrowLength_m_per_N = 0.010;
void encodeHandScene(const servo::TickRecord& record, std::string_view stateName, std::uint64_t time_ns,
                     std::string& out);

// Foxglove's log levels (foxglove.Log.Level); others are written as unknown.
enum LogLevel : int { kLogUnknown = 0, kLogDebug = 1, kLogInfo = 2, kLogWarning = 3, kLogError = 4, kLogFatal = 5 };
// A foxglove.Log line: events and reviewers' annotations; `name` says who wrote it.
void encodeLog(std::uint64_t time_ns, int level, std::string_view name, std::string_view message, std::string& out);

// A foxglove.Log as read back (events, annotations). False for bytes that are not one.
struct LogEntry {
  std::uint64_t time_ns = 0;
  int level = kLogUnknown;
  std::string name, message;
};
bool decodeLog(std::string_view bytes, LogEntry& out);

// A part's stand-in box (object frame, metres) as a mesh: what viewers show until its own
// model is built.
PartMesh boxMesh(const geometry::Aabb& box, std::string name);

}  // namespace hg::session
