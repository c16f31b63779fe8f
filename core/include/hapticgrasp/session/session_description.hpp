#pragma once
// What a recording says about its session, so that it is self-contained: the parts (each
// one's shape as BREP, attached to the file once per distinct shape; its back end, mass
// properties and initial pose), the device's spec, the grasp method and every parameter,
// the servo's rate, the software that recorded it. Replay rebuilds the same scene and
// loop from it; `recording info`, the report and the Review panel read it.
//
// Stored in the MCAP file as a Metadata record named kSessionMetadata whose "json" entry
// holds toJson(); doubles are written in their shortest round-trip form, so a replay gets
// the parameters bit for bit.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/contact/carried_contact.hpp"
#include "hapticgrasp/contact/contact_model.hpp"
#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/units.hpp"
#include "hapticgrasp/grasp/grasp_parameters.hpp"
#include "hapticgrasp/grasp/multi_finger/multi_finger_scene.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/scene/scene.hpp"

namespace hg::servo {
class ServoLoop;
}

namespace hg::session {

// A recording that cannot be read or used, in one line.
class SessionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr std::string_view kSessionMetadata = "hapticgrasp.session";
inline constexpr std::string_view kBrepMediaType = "model/x-opencascade-brep";

struct RecordedPart {
  std::string name;
  std::string attachment;          // the attachment holding its BREP ("parts/<hash>.brep"); "" for a stand-in
  std::string brep;                // BREP text in `unit`, without placement (not in the JSON: attached)
  geometry::LengthUnit unit = geometry::LengthUnit::Millimetre;
  std::string backend;             // penetration back end at the start: "exact", "analytic", "box", ...
  bool coarse = false;             // a stand-in box at the start (its own model came later)
  geometry::Aabb bounds;           // object frame, metres
  geometry::MassProperties mass;
  grasp::PartPose initialPose;
  std::string contentHash;         // FNV-1a of the binary BREP, hex: one attachment per distinct shape
  int faces = 0;                   // the model's face count (0 for a stand-in): with the volume and
                                   // centre of gravity, what tells a changed part (session review)
};

struct SessionDescription {
  std::string document;            // the FreeCAD document, "" from the command line
  std::string software;            // "hapticgrasp 0.1.0"
  std::string build;               // git revision, compiler, build type
  std::string created_utc;         // ISO 8601
  std::string method = "two-finger";  // GraspEngine::name()
  int fingertips = 2;
  double rate_hz = 2000;
  double watchdogRamp_s = 0.010;
  bool passivityController = false;
  device::DeviceSpec device;
  grasp::GraspParameters twoFinger;
  grasp::multi_finger::MultiFingerSceneParams multiFinger;
  // Part-to-part contact (contact/carried_contact.hpp): on, the parts' contact shells are
  // rebuilt with `contactModel` (deterministic: the same shell from the same BREP) and the
  // engine couples carried parts with `contactConfig`. Recordings before it: off.
  bool contact = false;
  contact::ContactModelOptions contactModel;
  contact::CarriedContactConfig contactConfig;
  std::vector<RecordedPart> parts;
  // The scene's model publications (Scene::publications()) made before `parts` was taken:
  // the ones after it are recorded as model swaps (session/model_swap_message.hpp).
  std::uint64_t scenePublications = 0;
  std::vector<std::string> partNames() const;
};

std::string toJson(const SessionDescription& description);
// Throws SessionError naming the field that is missing or wrong.
SessionDescription sessionFromJson(std::string_view json);

// The parts of `scene` as they stand now (binary BREP from each model's shape; a stand-in
// without a model is recorded coarse, by its box). Name: the model's, else "part<i>".
std::vector<RecordedPart> describeParts(const grasp::Scene& scene);
RecordedPart describePart(const grasp::ScenePart& part, std::string name);

// One part as the description's JSON has it (without its BREP); partFromJson throws
// SessionError naming what is missing.
std::string partToJson(const RecordedPart& part);
RecordedPart partFromJson(std::string_view json);

// A recorded part's binary BREP as OCCT's text BREP (geometry only, no triangulation): what
// FreeCAD 0.20 reads (Part.Shape.importBrepFromString); its importBinary reads only the
// pre-7.6 BinTools_ShapeSet layout, not what BinTools::Write writes now. A recording may
// come from anyone: the shape first passes the checks a session's part load makes
// (PartModel::fromShape), so that a damaged one never reaches FreeCAD, whose display would
// mesh it with no limit (an edge 98 times round kept BRepMesh busy for good). Throws
// SessionError, naming the part, when the bytes are not a shape or the checks refuse it.
std::string brepAsText(const RecordedPart& part);

// Hex FNV-1a 64 of `text`: identical shapes share one attachment.
std::string contentHash(std::string_view text);

// "0.1.0", and how it was built ("git 1a2b3c4, GCC 12.2.0, Release").
const char* softwareVersion();
const char* softwareBuild();

// Now, as ISO 8601 UTC ("2026-11-24T10:15:03Z").
std::string utcNow();

}  // namespace hg::session
