#include "hapticgrasp/session/session_description.hpp"

#include <BinTools.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS_Shape.hxx>

#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <ctime>
#include <nlohmann/json.hpp>
#include <sstream>

#include "hapticgrasp/geometry/display_shape.hpp"
#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::session {
namespace {

using nlohmann::json;

// JSON has no infinity or NaN (an unbounded workspace is infinite): those go as strings.
json num(double v) {
  if (std::isfinite(v)) return v;
  return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
}
bool fromNum(const json& v, double& out) {
  if (v.is_number()) {
    out = v.get<double>();
    return true;
  }
  if (!v.is_string()) return false;
  const std::string s = v.get<std::string>();
  if (s == "inf") out = std::numeric_limits<double>::infinity();
  else if (s == "-inf") out = -std::numeric_limits<double>::infinity();
  else if (s == "nan") out = std::numeric_limits<double>::quiet_NaN();
  else return false;
  return true;
}
json vec(const Vec3& v) { return json::array({num(v.x()), num(v.y()), num(v.z())}); }
json mat(const Mat3& m) {
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(json::array({num(m(r, 0)), num(m(r, 1)), num(m(r, 2))}));
  return rows;
}

// Readers of other people's files: every access names what is missing.
const json& field(const json& j, const char* name) {
  if (!j.is_object() || !j.contains(name)) throw SessionError(std::string("session metadata: no '") + name + "'");
  return j.at(name);
}
double number(const json& j, const char* name) {
  double out = 0;
  if (!fromNum(field(j, name), out)) throw SessionError(std::string("session metadata: '") + name + "' is not a number");
  return out;
}
Vec3 toVec(const json& j, const char* name) {
  const json& v = field(j, name);
  Vec3 out;
  if (!v.is_array() || v.size() != 3 || !fromNum(v[0], out.x()) || !fromNum(v[1], out.y()) || !fromNum(v[2], out.z()))
    throw SessionError(std::string("session metadata: '") + name + "' is not a 3-vector");
  return out;
}
Mat3 toMat(const json& j, const char* name) {
  const json& v = field(j, name);
  if (!v.is_array() || v.size() != 3) throw SessionError(std::string("session metadata: '") + name + "' is not a 3x3 matrix");
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    const json row = json{{"r", v[static_cast<std::size_t>(r)]}};
    m.row(r) = toVec(row, "r").transpose();
  }
  return m;
}

json poseJson(const grasp::PartPose& p) { return {{"position", vec(p.position)}, {"rotation", mat(p.rotation)}}; }
grasp::PartPose poseFrom(const json& j) { return {toMat(j, "rotation"), toVec(j, "position")}; }

json deviceJson(const device::DeviceSpec& d) {
  return {{"name", d.name},
          {"force_output", d.forceOutput},
          {"fingertips", d.fingertips},
          {"max_force_N", num(d.maxForce_N)},
          {"max_torque_Nm", num(d.maxTorque_Nm)},
          {"max_stiffness_N_per_m", num(d.maxStiffness_N_per_m)},
          {"max_damping_Ns_per_m", num(d.maxDamping_Ns_per_m)},
          {"timeout_s", num(d.timeout_s)},
          {"workspace", {{"min", vec(d.workspace.min)}, {"max", vec(d.workspace.max)}}}};
}
device::DeviceSpec deviceFrom(const json& j) {
  device::DeviceSpec d;
  d.name = field(j, "name").get<std::string>();
  d.forceOutput = field(j, "force_output").get<bool>();
  d.fingertips = static_cast<int>(number(j, "fingertips"));
  d.maxForce_N = number(j, "max_force_N");
  d.maxTorque_Nm = number(j, "max_torque_Nm");
  d.maxStiffness_N_per_m = number(j, "max_stiffness_N_per_m");
  d.maxDamping_Ns_per_m = number(j, "max_damping_Ns_per_m");
  d.timeout_s = number(j, "timeout_s");
  const json& w = field(j, "workspace");
  d.workspace.min = toVec(w, "min");
  d.workspace.max = toVec(w, "max");
  return d;
}

json twoFingerJson(const grasp::GraspParameters& p) {
  return {{"K_c", num(p.K_c)}, {"B_c", num(p.B_c)}, {"K_g", num(p.K_g)}, {"B_g", num(p.B_g)}, {"d_h", num(p.d_h)}, {"K_ox", num(p.K_ox)},
          {"K_oe", num(p.K_oe)},
          {"rotational_spring", p.rotationalSpring == grasp::RotationalSpring::PaperRpy ? "paper-rpy" : "rotation-vector"},
          {"gravity", vec(p.gravity)}, {"rate_cutoff_Hz", num(p.rateCutoff_Hz)},
          {"tracking_hysteresis_m", num(p.trackingHysteresis_m)}, {"detach_distance_m", num(p.detachDistance_m)},
          {"box_margin_m", num(p.boxMargin_m)}, {"min_finger_distance_m", num(p.minFingerDistance_m)},
          {"min_wrist_sine", num(p.minWristSine)}};
}
grasp::GraspParameters twoFingerFrom(const json& j) {
  grasp::GraspParameters p;
  p.K_c = number(j, "K_c");
  p.B_c = number(j, "B_c");
  p.K_g = number(j, "K_g");
  p.B_g = number(j, "B_g");
  p.d_h = number(j, "d_h");
  p.K_ox = number(j, "K_ox");
  p.K_oe = number(j, "K_oe");
  p.rotationalSpring = field(j, "rotational_spring").get<std::string>() == "paper-rpy"
                           ? grasp::RotationalSpring::PaperRpy
                           : grasp::RotationalSpring::RotationVector;
  p.gravity = toVec(j, "gravity");
  p.rateCutoff_Hz = number(j, "rate_cutoff_Hz");
  p.trackingHysteresis_m = number(j, "tracking_hysteresis_m");
  p.detachDistance_m = number(j, "detach_distance_m");
  p.boxMargin_m = number(j, "box_margin_m");
  p.minFingerDistance_m = number(j, "min_finger_distance_m");
  p.minWristSine = number(j, "min_wrist_sine");
  return p;
}

json multiFingerJson(const grasp::multi_finger::MultiFingerSceneParams& s) {
  const auto& p = s.grasp;
  const auto& d = p.distribution;
  return {{"method", p.method == grasp::multi_finger::Method::Conventional ? "conventional" : "proposed"},
          {"stiffness", num(p.stiffness)}, {"friction", num(p.friction)}, {"torsional_friction", num(p.torsionalFriction)},
          {"dynamics_stiffness", num(p.dynamicsStiffness)}, {"rotational_stiffness", num(p.rotationalStiffness)},
          {"damping_ratio", num(p.dampingRatio)}, {"shell_velocity_tau", num(p.shellVelocityTau)},
          {"gravity", vec(p.gravity)}, {"contact_damping_ratio", num(p.contactDampingRatio)},
          {"distribution", {{"gamma1", num(d.gamma1)}, {"min_lever_arm", num(d.minLeverArm)}, {"gamma2", num(d.gamma2)},
                            {"gamma3", num(d.gamma3)}, {"max_iterations", d.maxIterations}}},
          {"box_margin_m", num(s.boxMargin_m)}};
}
grasp::multi_finger::MultiFingerSceneParams multiFingerFrom(const json& j) {
  grasp::multi_finger::MultiFingerSceneParams s;
  auto& p = s.grasp;
  p.method = field(j, "method").get<std::string>() == "conventional" ? grasp::multi_finger::Method::Conventional
                                                                      : grasp::multi_finger::Method::Proposed;
  p.stiffness = number(j, "stiffness");
  p.friction = number(j, "friction");
  p.torsionalFriction = number(j, "torsional_friction");
  p.dynamicsStiffness = number(j, "dynamics_stiffness");
  p.rotationalStiffness = number(j, "rotational_stiffness");
  p.dampingRatio = number(j, "damping_ratio");
  p.shellVelocityTau = number(j, "shell_velocity_tau");
  p.gravity = toVec(j, "gravity");
  p.contactDampingRatio = number(j, "contact_damping_ratio");
  const json& d = field(j, "distribution");
  p.distribution.gamma1 = number(d, "gamma1");
  p.distribution.minLeverArm = number(d, "min_lever_arm");
  p.distribution.gamma2 = number(d, "gamma2");
  p.distribution.gamma3 = number(d, "gamma3");
  p.distribution.maxIterations = static_cast<int>(number(d, "max_iterations"));
  s.boxMargin_m = number(j, "box_margin_m");
  return s;
}

json contactJson(const SessionDescription& d) {
  if (!d.contact) return nullptr;
  const contact::ContactModelOptions& m = d.contactModel;
  const contact::CouplingParameters& c = d.contactConfig.coupling;
  const contact::ContactQueryConfig& q = d.contactConfig.query;
  return {{"constrain", d.contactConfig.constrain},
          {"shell", {{"max_points", m.maxPoints}, {"edge_density", num(m.edgeDensity)}, {"sharp_angle_rad", num(m.sharpAngle_rad)}}},
          {"coupling",
           {{"k_t", num(c.stiffness.translational_N_m)}, {"k_r", num(c.stiffness.rotational_Nm_rad)},
            {"b_t", num(c.damping_Ns_m)}, {"b_r", num(c.rotationalDamping_Nms_rad)}, {"friction", num(c.friction)},
            {"margin_m", num(c.margin_m)}, {"max_substeps", c.maxSubsteps}, {"solver_iterations", c.solverIterations},
            {"row_slack_m", num(c.rowSlack_m)}, {"max_rows", c.maxRows}, {"max_force_N", num(c.maxForce_N)},
            {"max_torque_Nm", num(c.maxTorque_Nm)}, {"passivity_controller", c.passivityController},
            {"max_passivity_damping_Ns_m", num(c.maxPassivityDamping_Ns_m)},
            {"max_rotational_passivity_damping_Nms_rad", num(c.maxRotationalPassivityDamping_Nms_rad)}}},
          {"query",
           {{"max_points", q.maxPoints}, {"max_nearby", q.maxNearby}, {"max_contacts", q.maxContacts},
            {"clearance_range_m", num(q.clearanceRange_m)}, {"requery_m", num(q.requery_m)},
            {"max_predict_m", num(q.maxPredict_m)}, {"query_budget", q.queryBudget}}}};
}
void contactFrom(const json& j, SessionDescription& d) {
  d.contact = j.is_object();
  if (!d.contact) return;
  // Counts size buffers: one beyond its range would let a hostile recording ask for any memory.
  const auto integer = [](const json& o, const char* name, int lo, int hi) {
    const double v = number(o, name);
    if (!(v >= lo && v <= hi))
      throw SessionError(std::string("session metadata: contact '") + name + "' is not within " + std::to_string(lo) +
                         "-" + std::to_string(hi));
    return static_cast<int>(v);
  };
  d.contactConfig.constrain = field(j, "constrain").get<bool>();
  const json& m = field(j, "shell");
  d.contactModel.maxPoints = integer(m, "max_points", 8, 65536);
  d.contactModel.edgeDensity = number(m, "edge_density");
  d.contactModel.sharpAngle_rad = number(m, "sharp_angle_rad");
  const json& c = field(j, "coupling");
  contact::CouplingParameters& p = d.contactConfig.coupling;
  p.stiffness.translational_N_m = number(c, "k_t");
  p.stiffness.rotational_Nm_rad = number(c, "k_r");
  p.damping_Ns_m = number(c, "b_t");
  p.rotationalDamping_Nms_rad = number(c, "b_r");
  p.friction = number(c, "friction");
  p.margin_m = number(c, "margin_m");
  p.maxSubsteps = integer(c, "max_substeps", 1, 64);
  p.solverIterations = integer(c, "solver_iterations", 1, 1000);
  p.rowSlack_m = number(c, "row_slack_m");
  p.maxRows = integer(c, "max_rows", 1, 4096);
  p.maxForce_N = number(c, "max_force_N");
  p.maxTorque_Nm = number(c, "max_torque_Nm");
  p.passivityController = field(c, "passivity_controller").get<bool>();
  p.maxPassivityDamping_Ns_m = number(c, "max_passivity_damping_Ns_m");
  p.maxRotationalPassivityDamping_Nms_rad = number(c, "max_rotational_passivity_damping_Nms_rad");
  const json& q = field(j, "query");
  contact::ContactQueryConfig& r = d.contactConfig.query;
  r.maxPoints = integer(q, "max_points", 1, 65536);
  r.maxNearby = integer(q, "max_nearby", 1, 64);
  r.maxContacts = integer(q, "max_contacts", 1, 4096);
  r.clearanceRange_m = number(q, "clearance_range_m");
  r.requery_m = number(q, "requery_m");
  r.maxPredict_m = number(q, "max_predict_m");
  r.queryBudget = integer(q, "query_budget", 0, 65536);
}

json partJson(const RecordedPart& p) {
  return {{"name", p.name},
          {"attachment", p.attachment},
          {"unit", p.unit == geometry::LengthUnit::Metre ? "m" : "mm"},
          {"backend", p.backend},
          {"coarse", p.coarse},
          {"bounds", {{"min", vec(p.bounds.min)}, {"max", vec(p.bounds.max)}}},
          {"mass", {{"volume_m3", num(p.mass.volume_m3)}, {"mass_kg", num(p.mass.mass_kg)}, {"centre_m", vec(p.mass.centre_m)},
                    {"inertia_kgm2", mat(p.mass.inertia_kgm2)}}},
          {"initial_pose", poseJson(p.initialPose)},
          {"content_hash", p.contentHash},
          {"faces", p.faces}};
}
RecordedPart partFrom(const json& j) {
  RecordedPart p;
  p.name = field(j, "name").get<std::string>();
  p.attachment = field(j, "attachment").get<std::string>();
  p.unit = field(j, "unit").get<std::string>() == "m" ? geometry::LengthUnit::Metre : geometry::LengthUnit::Millimetre;
  p.backend = field(j, "backend").get<std::string>();
  p.coarse = field(j, "coarse").get<bool>();
  const json& b = field(j, "bounds");
  p.bounds.min = toVec(b, "min");
  p.bounds.max = toVec(b, "max");
  const json& m = field(j, "mass");
  p.mass.volume_m3 = number(m, "volume_m3");
  p.mass.mass_kg = number(m, "mass_kg");
  p.mass.centre_m = toVec(m, "centre_m");
  p.mass.inertia_kgm2 = toMat(m, "inertia_kgm2");
  p.initialPose = poseFrom(field(j, "initial_pose"));
  p.contentHash = field(j, "content_hash").get<std::string>();
  p.faces = j.contains("faces") ? static_cast<int>(number(j, "faces")) : 0;  // recordings before faces: unknown
  return p;
}

}  // namespace

std::vector<std::string> SessionDescription::partNames() const {
  std::vector<std::string> names;
  names.reserve(parts.size());
  for (const RecordedPart& p : parts) names.push_back(p.name);
  return names;
}

std::string toJson(const SessionDescription& d) {
  json parts = json::array();
  for (const RecordedPart& p : d.parts) parts.push_back(partJson(p));
  const json j = {{"format", 1},
                  {"document", d.document},
                  {"software", d.software},
                  {"build", d.build},
                  {"created_utc", d.created_utc},
                  {"method", d.method},
                  {"fingertips", d.fingertips},
                  {"rate_hz", num(d.rate_hz)},
                  {"watchdog_ramp_s", num(d.watchdogRamp_s)},
                  {"passivity_controller", d.passivityController},
                  {"device", deviceJson(d.device)},
                  {"two_finger", twoFingerJson(d.twoFinger)},
                  {"multi_finger", multiFingerJson(d.multiFinger)},
                  {"contact", contactJson(d)},
                  {"parts", parts},
                  {"scene_publications", d.scenePublications}};
  return j.dump();
}

SessionDescription sessionFromJson(std::string_view text) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) throw SessionError("session metadata: not a JSON object");
  try {
    if (number(j, "format") != 1) throw SessionError("session metadata: format " + field(j, "format").dump() + " is not 1");
    SessionDescription d;
    d.document = field(j, "document").get<std::string>();
    d.software = field(j, "software").get<std::string>();
    d.build = field(j, "build").get<std::string>();
    d.created_utc = field(j, "created_utc").get<std::string>();
    d.method = field(j, "method").get<std::string>();
    d.fingertips = static_cast<int>(number(j, "fingertips"));
    d.rate_hz = number(j, "rate_hz");
    d.watchdogRamp_s = number(j, "watchdog_ramp_s");
    d.passivityController = field(j, "passivity_controller").get<bool>();
    d.device = deviceFrom(field(j, "device"));
    d.twoFinger = twoFingerFrom(field(j, "two_finger"));
    d.multiFinger = multiFingerFrom(field(j, "multi_finger"));
    if (j.contains("contact")) contactFrom(j["contact"], d);
    const json& parts = field(j, "parts");
    if (!parts.is_array()) throw SessionError("session metadata: 'parts' is not a list");
    for (const json& p : parts) d.parts.push_back(partFrom(p));
    if (j.contains("scene_publications")) d.scenePublications = field(j, "scene_publications").get<std::uint64_t>();
    return d;
  } catch (const json::exception& e) {  // a field of the wrong type
    throw SessionError(std::string("session metadata: ") + e.what());
  }
}

std::vector<RecordedPart> describeParts(const grasp::Scene& scene) {
  std::vector<RecordedPart> parts;
  parts.reserve(scene.size());
  for (std::size_t i = 0; i < scene.size(); ++i) {
    const grasp::ScenePart& s = scene.part(i);
    parts.push_back(describePart(s, s.model ? s.model->name() : "part" + std::to_string(i)));
  }
  return parts;
}

RecordedPart describePart(const grasp::ScenePart& s, std::string name) {
  RecordedPart p;
  p.name = std::move(name);
  p.coarse = s.coarse || !s.model;
  p.backend = s.penetration ? std::string(s.penetration->name()) : "box";
  p.bounds = s.bounds;
  p.mass = s.mass;
  p.initialPose = s.initialPose;
  if (s.model) {
    // Binary BREP: exact to the bit (text BREP rounds to 15 digits), so replay rebuilds
    // the very same surfaces. FreeCAD reads it with Part.Shape().importBinary().
    std::ostringstream out(std::ios::binary);
    BinTools::Write(s.model->shape(), out);
    p.brep = std::move(out).str();
    p.unit = s.model->metresPerUnit() == 1.0 ? geometry::LengthUnit::Metre : geometry::LengthUnit::Millimetre;
    p.contentHash = contentHash(p.brep);
    p.attachment = "parts/" + p.contentHash + ".brep";
    p.faces = s.model->faces().Extent();
  }
  return p;
}

std::string brepAsText(const RecordedPart& part) {
  try {
    return geometry::displayableBrepText(part.brep, part.unit, part.name);
  } catch (const geometry::GeometryError& e) {
    throw SessionError("part '" + part.name + "': its recorded shape " + e.what());
  }
}

std::string partToJson(const RecordedPart& part) { return partJson(part).dump(); }

RecordedPart partFromJson(std::string_view text) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) throw SessionError("part description: not a JSON object");
  try {
    return partFrom(j);
  } catch (const json::exception& e) {
    throw SessionError(std::string("part description: ") + e.what());
  }
}

std::string contentHash(std::string_view text) {
  std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a 64: fast, stable, enough to tell shapes apart
  for (const unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

std::string utcNow() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace hg::session
