#include "hapticgrasp/device/hid_layout.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "hapticgrasp/install_layout.hpp"

namespace hg::device {
namespace {

using nlohmann::json;

double monotonicSeconds() noexcept {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

// ---- parsing helpers: every error names its field -----------------------------------

struct Ctx {
  std::string source;
  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw HidLayoutError(source, field, problem);
  }
};

std::string show(const json& j) {
  std::string s = j.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

void allowOnly(const Ctx& c, const json& obj, const std::string& where, std::initializer_list<const char*> keys) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool known = it.key() == "comment" || it.key() == "description";
    for (const char* k : keys) known |= it.key() == k;
    if (!known) c.fail(where.empty() ? it.key() : where + "." + it.key(), "unknown key");
  }
}

long long integer(const Ctx& c, const json& j, const std::string& field, long long lo, long long hi,
                  bool allowHexString = false) {
  long long v = 0;
  if (j.is_number_integer()) {
    v = j.get<long long>();
  } else if (allowHexString && j.is_string()) {
    const std::string s = j.get<std::string>();
    char* end = nullptr;
    const bool hex = s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
    v = std::strtoll(s.c_str(), &end, hex ? 16 : 10);
    if (s.empty() || !end || *end != '\0') c.fail(field, "expected an integer or a hex string like \"0x046d\", got " + show(j));
  } else if (j.is_number_float() && std::floor(j.get<double>()) == j.get<double>() && std::abs(j.get<double>()) < 1e15) {
    v = static_cast<long long>(j.get<double>());
  } else {
    c.fail(field, "expected an integer, got " + show(j));
  }
  if (v < lo || v > hi) c.fail(field, std::to_string(v) + " is out of range " + std::to_string(lo) + ".." + std::to_string(hi));
  return v;
}

double number(const Ctx& c, const json& j, const std::string& field) {
  if (!j.is_number()) c.fail(field, "expected a number, got " + show(j));
  const double v = j.get<double>();
  if (!std::isfinite(v)) c.fail(field, "must be finite");
  return v;
}

const json& required(const Ctx& c, const json& obj, const char* key, const std::string& where) {
  auto it = obj.find(key);
  if (it == obj.end()) c.fail(where.empty() ? key : where + "." + key, "missing");
  return *it;
}

Vec3 vec3(const Ctx& c, const json& j, const std::string& field) {
  if (!j.is_array() || j.size() != 3) c.fail(field, "expected [x, y, z], got " + show(j));
  return Vec3(number(c, j[0], field + "[0]"), number(c, j[1], field + "[1]"), number(c, j[2], field + "[2]"));
}

HidFieldType fieldType(const Ctx& c, const json& j, const std::string& field) {
  if (!j.is_string()) c.fail(field, "expected a type name, got " + show(j));
  const std::string s = j.get<std::string>();
  static const std::pair<const char*, HidFieldType> kTypes[] = {
      {"int8", HidFieldType::Int8},   {"uint8", HidFieldType::UInt8},   {"int16", HidFieldType::Int16},
      {"uint16", HidFieldType::UInt16}, {"int32", HidFieldType::Int32}, {"uint32", HidFieldType::UInt32},
      {"float32", HidFieldType::Float32}};
  for (const auto& [name, t] : kTypes)
    if (s == name) return t;
  c.fail(field, "unknown type '" + s + "' (int8, uint8, int16, uint16, int32, uint32, float32)");
}

HidEndian endian(const Ctx& c, const json& obj, const std::string& where) {
  auto it = obj.find("endian");
  if (it == obj.end()) return HidEndian::Little;
  if (*it == "little") return HidEndian::Little;
  if (*it == "big") return HidEndian::Big;
  c.fail(where + ".endian", "expected \"little\" or \"big\", got " + show(*it));
}

int axis(std::string_view s) {
  if (s == "x") return 0;
  if (s == "y") return 1;
  if (s == "z") return 2;
  return -1;
}

// "joint.3" -> 3 (limit exclusive), or -1.
int numbered(std::string_view s, std::string_view prefix, int limit) {
  if (s.substr(0, prefix.size()) != prefix) return -1;
  s.remove_prefix(prefix.size());
  if (s.empty() || s.size() > 2) return -1;
  int n = 0;
  for (char ch : s) {
    if (ch < '0' || ch > '9') return -1;
    n = n * 10 + (ch - '0');
  }
  return n < limit ? n : -1;
}

// "fingertip.3.x" with prefix "fingertip." -> {3, 0}; {-1, -1} when it is not one.
std::pair<int, int> extraFingertip(std::string_view name, std::string_view prefix) {
  if (name.substr(0, prefix.size()) != prefix || name.size() != prefix.size() + 3 || name[prefix.size() + 1] != '.')
    return {-1, -1};
  const int n = name[prefix.size()] - '0';
  const int a = axis(name.substr(prefix.size() + 2));
  if (n < 2 || n >= grasp::HandSample::kMaxFingertips || a < 0) return {-1, -1};
  return {n, a};
}

bool inputTarget(std::string_view name, HidInputField& f) {
  using T = HidInputField::Target;
  if (auto [n, a] = extraFingertip(name, "fingertip."); n >= 0)
    return f.target = T::Fingertip, f.fingertip = n, f.component = a, true;
  const auto dot = name.find('.');
  const std::string_view head = name.substr(0, dot);
  const std::string_view tail = dot == std::string_view::npos ? std::string_view{} : name.substr(dot + 1);
  if (name == "grip") return f.target = T::Grip, true;
  if (name == "buttons") return f.target = T::Buttons, true;
  if (int n = numbered(name, "button.", 32); n >= 0) return f.target = T::Button, f.component = n, true;
  if (int n = numbered(name, "joint.", DeviceSample::kMaxJoints); n >= 0) return f.target = T::Joint, f.component = n, true;
  const int a = axis(tail);
  if (head == "index" && a >= 0) return f.target = T::Index, f.component = a, true;
  if (head == "thumb" && a >= 0) return f.target = T::Thumb, f.component = a, true;
  if (head == "wrist" && a >= 0) return f.target = T::Wrist, f.component = a, true;
  if (head == "wrist") {
    if (tail == "roll") return f.target = T::WristAngle, f.component = 0, true;
    if (tail == "pitch") return f.target = T::WristAngle, f.component = 1, true;
    if (tail == "yaw") return f.target = T::WristAngle, f.component = 2, true;
  }
  return false;
}

bool outputSource(std::string_view name, HidOutputField& f) {
  using S = HidOutputField::Source;
  if (auto [n, a] = extraFingertip(name, "f_fingertip."); n >= 0)
    return f.source = S::FFingertip, f.fingertip = n, f.component = a, true;
  if (name == "f_grasp") return f.source = S::FGrasp, true;
  const auto dot = name.find('.');
  if (dot == std::string_view::npos) return false;
  const int a = axis(name.substr(dot + 1));
  if (a < 0) return false;
  const std::string_view head = name.substr(0, dot);
  f.component = a;
  if (head == "f_index") return f.source = S::FIndex, true;
  if (head == "f_thumb") return f.source = S::FThumb, true;
  if (head == "f_wrist") return f.source = S::FWrist, true;
  if (head == "m_wrist") return f.source = S::MWrist, true;
  return false;
}

// Common to input and output fields: offset, type, endian; checked against the report.
template <class Field>
void placeField(const Ctx& c, const json& j, const std::string& where, Field& f, long long reportSize,
                const char* sizeName, bool reportIdByte, int reportId) {
  f.type = fieldType(c, required(c, j, "type", where), where + ".type");
  f.endian = endian(c, j, where);
  f.offset = static_cast<int>(integer(c, required(c, j, "offset", where), where + ".offset", 0, 1 << 20));
  const int bytes = hidFieldSize(f.type);
  if (f.offset + bytes > reportSize)
    c.fail(where + ".offset", std::to_string(f.offset) + " + " + std::to_string(bytes) + " bytes exceeds " + sizeName +
                                  " " + std::to_string(reportSize));
  if (reportIdByte && f.offset == 0)
    c.fail(where + ".offset", "0 is the report ID byte (report ID " + std::to_string(reportId) + ")");
  if (auto it = j.find("scale"); it != j.end()) f.scale = number(c, *it, where + ".scale");
  if (auto it = j.find("bias"); it != j.end()) f.bias = number(c, *it, where + ".bias");
}

bool isInteger(HidFieldType t) { return t != HidFieldType::Float32; }

HidLayout parse(const json& root, const Ctx& c) {
  if (!root.is_object()) c.fail("(root)", "expected a JSON object");
  allowOnly(c, root, "",
            {"name", "match", "path", "input_report_id", "report_size", "fields", "force_output", "watchdog_ms",
             "limits", "hand", "$schema"});
  HidLayout L;
  L.source = c.source;

  const json& name = required(c, root, "name", "");
  if (!name.is_string() || name.get<std::string>().empty()) c.fail("name", "expected a non-empty string");
  L.name = name.get<std::string>();

  // match
  auto readPath = [&](const json& j, const std::string& field) {
    if (!j.is_string() || j.get<std::string>().empty()) c.fail(field, "expected a device path such as \"/dev/hidraw3\"");
    L.path = j.get<std::string>();
  };
  if (auto it = root.find("path"); it != root.end()) readPath(*it, "path");
  if (auto it = root.find("match"); it != root.end()) {
    if (!it->is_object()) c.fail("match", "expected an object {\"vendor_id\", \"product_id\"} or {\"path\"}");
    allowOnly(c, *it, "match", {"vendor_id", "product_id", "path"});
    if (auto p = it->find("path"); p != it->end()) readPath(*p, "match.path");
    if (auto v = it->find("vendor_id"); v != it->end())
      L.vendor_id = static_cast<std::uint16_t>(integer(c, *v, "match.vendor_id", 0, 0xffff, true));
    if (auto p = it->find("product_id"); p != it->end()) {
      if (!L.vendor_id) c.fail("match.product_id", "needs a vendor_id too");
      L.product_id = static_cast<std::uint16_t>(integer(c, *p, "match.product_id", 0, 0xffff, true));
    }
  }
  if (!L.vendor_id && L.path.empty()) c.fail("match", "missing: give match {vendor_id, product_id} or path");

  if (auto it = root.find("input_report_id"); it != root.end() && !it->is_null())
    L.input_report_id = static_cast<int>(integer(c, *it, "input_report_id", 0, 255));
  L.report_size = static_cast<int>(integer(c, required(c, root, "report_size", ""), "report_size", 1,
                                           static_cast<long long>(GenericHidDevice::kMaxReportSize)));

  const json& fields = required(c, root, "fields", "");
  if (!fields.is_array() || fields.empty()) c.fail("fields", "expected a non-empty array");
  std::set<std::string> seen;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string where = "fields[" + std::to_string(i) + "]";
    const json& j = fields[i];
    if (!j.is_object()) c.fail(where, "expected an object");
    allowOnly(c, j, where, {"name", "offset", "type", "endian", "scale", "bias"});
    HidInputField f;
    const json& n = required(c, j, "name", where);
    if (!n.is_string()) c.fail(where + ".name", "expected a string, got " + show(n));
    f.name = n.get<std::string>();
    if (!inputTarget(f.name, f))
      c.fail(where + ".name", "unknown input '" + f.name +
                                  "' (index.x|y|z, thumb.x|y|z, fingertip.2-4.x|y|z, wrist.x|y|z, wrist.roll|pitch|yaw, grip, buttons, "
                                  "button.N, joint.N)");
    if (!seen.insert(f.name).second) c.fail(where + ".name", "'" + f.name + "' is given twice");
    placeField(c, j, where, f, L.report_size, "report_size", L.input_report_id != 0, L.input_report_id);
    if (f.target == HidInputField::Target::Buttons && !isInteger(f.type))
      c.fail(where + ".type", "buttons need an integer type, not float32");
    L.fields.push_back(std::move(f));
  }

  if (auto it = root.find("force_output"); it != root.end() && !it->is_null()) {
    const json& fo = *it;
    if (!fo.is_object()) c.fail("force_output", "expected an object");
    allowOnly(c, fo, "force_output", {"report_id", "size", "fields"});
    HidForceOutput out;
    if (auto r = fo.find("report_id"); r != fo.end()) out.report_id = static_cast<int>(integer(c, *r, "force_output.report_id", 0, 255));
    out.size = static_cast<int>(integer(c, required(c, fo, "size", "force_output"), "force_output.size", 2,
                                        static_cast<long long>(GenericHidDevice::kMaxReportSize)));
    const json& of = required(c, fo, "fields", "force_output");
    if (!of.is_array() || of.empty()) c.fail("force_output.fields", "expected a non-empty array");
    std::set<std::string> outSeen;
    for (std::size_t i = 0; i < of.size(); ++i) {
      const std::string where = "force_output.fields[" + std::to_string(i) + "]";
      const json& j = of[i];
      if (!j.is_object()) c.fail(where, "expected an object");
      allowOnly(c, j, where, {"name", "offset", "type", "endian", "scale", "bias"});
      HidOutputField f;
      const json& n = required(c, j, "name", where);
      if (!n.is_string()) c.fail(where + ".name", "expected a string, got " + show(n));
      f.name = n.get<std::string>();
      if (!outputSource(f.name, f))
        c.fail(where + ".name", "unknown output '" + f.name + "' (f_index.x|y|z, f_thumb.x|y|z, f_fingertip.2-4.x|y|z, f_wrist.x|y|z, m_wrist.x|y|z, f_grasp)");
      if (!outSeen.insert(f.name).second) c.fail(where + ".name", "'" + f.name + "' is given twice");
      placeField(c, j, where, f, out.size, "force_output.size", true, out.report_id);
      if (f.scale == 0) c.fail(where + ".scale", "must be non-zero (raw = (value - bias) / scale)");
      out.fields.push_back(std::move(f));
    }
    L.force_output = std::move(out);
  }

  if (auto it = root.find("watchdog_ms"); it != root.end()) {
    L.watchdog_ms = number(c, *it, "watchdog_ms");
    if (L.watchdog_ms <= 0 || L.watchdog_ms > 60000) c.fail("watchdog_ms", "must be in (0, 60000]");
  }

  L.spec.name = L.name;
  L.spec.forceOutput = L.force_output.has_value();
  L.spec.timeout_s = L.watchdog_ms / 1000.0;
  if (auto it = root.find("limits"); it != root.end()) {
    const json& lim = *it;
    if (!lim.is_object()) c.fail("limits", "expected an object");
    allowOnly(c, lim, "limits", {"max_force_N", "max_torque_Nm", "max_stiffness_N_per_m", "max_damping_Ns_per_m", "workspace"});
    auto positive = [&](const char* key, double& dst) {
      if (auto v = lim.find(key); v != lim.end()) {
        dst = number(c, *v, std::string("limits.") + key);
        if (dst < 0) c.fail(std::string("limits.") + key, "must not be negative");
      }
    };
    positive("max_force_N", L.spec.maxForce_N);
    positive("max_torque_Nm", L.spec.maxTorque_Nm);
    positive("max_stiffness_N_per_m", L.spec.maxStiffness_N_per_m);
    positive("max_damping_Ns_per_m", L.spec.maxDamping_Ns_per_m);
    if (auto w = lim.find("workspace"); w != lim.end()) {
      if (!w->is_object()) c.fail("limits.workspace", "expected {\"min\": [x,y,z], \"max\": [x,y,z]}");
      allowOnly(c, *w, "limits.workspace", {"min", "max"});
      L.spec.workspace.min = vec3(c, required(c, *w, "min", "limits.workspace"), "limits.workspace.min");
      L.spec.workspace.max = vec3(c, required(c, *w, "max", "limits.workspace"), "limits.workspace.max");
      if (L.spec.workspace.empty()) c.fail("limits.workspace", "min exceeds max");
    }
  }
  if (auto it = root.find("hand"); it != root.end()) {
    if (!it->is_object()) c.fail("hand", "expected an object");
    allowOnly(c, *it, "hand", {"grip_width_m", "grip_centre_wrist"});
    if (auto v = it->find("grip_width_m"); v != it->end()) {
      L.gripWidth_m = number(c, *v, "hand.grip_width_m");
      if (L.gripWidth_m < 0) c.fail("hand.grip_width_m", "must not be negative");
    }
    if (auto v = it->find("grip_centre_wrist"); v != it->end()) L.gripCentre_wrist = vec3(c, *v, "hand.grip_centre_wrist");
  }
  bool extra[grasp::HandSample::kMaxFingertips] = {};
  for (const auto& f : L.fields) {
    L.directFingertips |= f.target == HidInputField::Target::Index || f.target == HidInputField::Target::Thumb;
    if (f.target == HidInputField::Target::Fingertip) extra[f.fingertip] = true;
  }
  for (int n = 2; n < grasp::HandSample::kMaxFingertips; ++n) {
    if (!extra[n]) continue;
    if (!L.directFingertips) c.fail("fields", "fingertip." + std::to_string(n) + ".* needs index.* and thumb.* fields");
    if (n > 2 && !extra[n - 1])
      c.fail("fields", "fingertip." + std::to_string(n) + ".* given without fingertip." + std::to_string(n - 1) + ".*");
    L.spec.fingertips = n + 1;
  }
  return L;
}

Vec3* commandVector(DeviceCommand& c, const HidOutputField& f) noexcept {
  using S = HidOutputField::Source;
  switch (f.source) {
    case S::FIndex: return &c.f_index;
    case S::FThumb: return &c.f_thumb;
    case S::FFingertip: return &c.fingertipForce(f.fingertip);
    case S::FWrist: return &c.f_wrist;
    case S::MWrist: return &c.m_wrist;
    default: return nullptr;
  }
}

Vec3 limitNorm(const Vec3& v, double limit) noexcept {
  if (!v.allFinite()) return Vec3::Zero();
  const double n = v.norm();
  return n > limit ? Vec3(v * (limit / n)) : v;
}

}  // namespace

// ---- public -------------------------------------------------------------------------

int hidFieldSize(HidFieldType type) noexcept {
  switch (type) {
    case HidFieldType::Int8:
    case HidFieldType::UInt8: return 1;
    case HidFieldType::Int16:
    case HidFieldType::UInt16: return 2;
    default: return 4;
  }
}

const char* hidFieldTypeName(HidFieldType type) noexcept {
  switch (type) {
    case HidFieldType::Int8: return "int8";
    case HidFieldType::UInt8: return "uint8";
    case HidFieldType::Int16: return "int16";
    case HidFieldType::UInt16: return "uint16";
    case HidFieldType::Int32: return "int32";
    case HidFieldType::UInt32: return "uint32";
    default: return "float32";
  }
}

HidLayoutError::HidLayoutError(const std::string& source, std::string field, const std::string& problem)
    : std::runtime_error((source.empty() ? "" : source + ": ") + field + ": " + problem), field_(std::move(field)) {}

bool HidLayout::matches(const HidDeviceInfo& info) const noexcept {
  if (!path.empty() && info.path != path) return false;
  if (vendor_id && info.vendor_id != *vendor_id) return false;
  if (product_id && info.product_id != *product_id) return false;
  return !path.empty() || vendor_id.has_value();
}

HidLayout parseHidLayout(std::string_view jsonText, const std::string& source) {
  const Ctx c{source};
  json root;
  try {
    root = json::parse(jsonText.begin(), jsonText.end(), nullptr, true, /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    c.fail("(json)", std::string("syntax error: ") + e.what());
  } catch (const json::exception& e) {
    // A number beyond a double ("watchdog_ms": 1e400) is not a parse_error but out_of_range
    // (found by fuzz_hid_layout): still a file that does not read, named as such.
    c.fail("(json)", std::string("number out of range: ") + e.what());
  }
  return parse(root, c);
}

HidLayout loadHidLayout(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw HidLayoutError(file.string(), "(file)", "cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return parseHidLayout(text.str(), file.string());
}

HidLayoutSet loadHidLayoutDirectory(const std::filesystem::path& directory) {
  HidLayoutSet set;
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (std::filesystem::directory_iterator it(directory, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".json") files.push_back(it->path());
  if (ec) {
    set.errors.push_back(directory.string() + ": " + ec.message());
    return set;
  }
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    try {
      set.layouts.push_back(loadHidLayout(f));
    } catch (const std::exception& e) {
      set.errors.push_back(e.what());
    }
  }
  return set;
}

std::filesystem::path defaultHidLayoutDirectory() {
  return hg::resourcesDir() / "devices";
}

double decodeHidValue(const std::uint8_t* p, HidFieldType type, HidEndian endian) noexcept {
  const int n = hidFieldSize(type);
  std::uint32_t u = 0;
  for (int i = 0; i < n; ++i) {
    const int shift = endian == HidEndian::Little ? 8 * i : 8 * (n - 1 - i);
    u |= std::uint32_t(p[i]) << shift;
  }
  switch (type) {
    case HidFieldType::Int8: return static_cast<std::int8_t>(u);
    case HidFieldType::UInt8: return static_cast<std::uint8_t>(u);
    case HidFieldType::Int16: return static_cast<std::int16_t>(u);
    case HidFieldType::UInt16: return static_cast<std::uint16_t>(u);
    case HidFieldType::Int32: return static_cast<std::int32_t>(u);
    case HidFieldType::UInt32: return u;
    default: return std::bit_cast<float>(u);
  }
}

void encodeHidValue(double raw, std::uint8_t* p, HidFieldType type, HidEndian endian) noexcept {
  std::uint32_t u = 0;
  auto sat = [&](double lo, double hi) { return std::isnan(raw) ? 0.0 : std::clamp(std::round(raw), lo, hi); };
  switch (type) {
    case HidFieldType::Int8: u = static_cast<std::uint8_t>(static_cast<std::int8_t>(sat(-128, 127))); break;
    case HidFieldType::UInt8: u = static_cast<std::uint8_t>(sat(0, 255)); break;
    case HidFieldType::Int16: u = static_cast<std::uint16_t>(static_cast<std::int16_t>(sat(-32768, 32767))); break;
    case HidFieldType::UInt16: u = static_cast<std::uint16_t>(sat(0, 65535)); break;
    case HidFieldType::Int32: u = static_cast<std::uint32_t>(static_cast<std::int32_t>(sat(-2147483648.0, 2147483647.0))); break;
    case HidFieldType::UInt32: u = static_cast<std::uint32_t>(sat(0, 4294967295.0)); break;
    default: {
      const double m = std::numeric_limits<float>::max();
      u = std::bit_cast<std::uint32_t>(static_cast<float>(std::isnan(raw) ? 0.0 : std::clamp(raw, -m, m)));
    }
  }
  const int n = hidFieldSize(type);
  for (int i = 0; i < n; ++i) {
    const int shift = endian == HidEndian::Little ? 8 * i : 8 * (n - 1 - i);
    p[i] = static_cast<std::uint8_t>(u >> shift);
  }
}

bool decodeInputReport(const HidLayout& L, const std::uint8_t* data, std::size_t size, DeviceSample& sample) noexcept {
  using T = HidInputField::Target;
  if (!data || size != static_cast<std::size_t>(L.report_size)) return false;
  if (L.input_report_id != 0 && data[0] != L.input_report_id) return false;
  Vec3 index = Vec3::Zero(), thumb = Vec3::Zero(), wrist = Vec3::Zero(), rpy = Vec3::Zero();
  Vec3 extra[grasp::HandSample::kMaxFingertips] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  double grip = L.gripWidth_m;
  std::uint32_t buttons = 0;
  double joints[DeviceSample::kMaxJoints] = {};
  int jointCount = 0;
  for (const auto& f : L.fields) {
    const double raw = decodeHidValue(data + f.offset, f.type, f.endian);
    const double v = raw * f.scale + f.bias;
    switch (f.target) {
      case T::Index: index[f.component] = v; break;
      case T::Thumb: thumb[f.component] = v; break;
      case T::Fingertip: extra[f.fingertip][f.component] = v; break;
      case T::Wrist: wrist[f.component] = v; break;
      case T::WristAngle: rpy[f.component] = v; break;
      case T::Grip: grip = v; break;
      case T::Buttons: buttons |= static_cast<std::uint32_t>(static_cast<std::int64_t>(raw)); break;
      case T::Button:
        if (raw != 0) buttons |= std::uint32_t(1) << f.component;
        break;
      case T::Joint:
        joints[f.component] = v;
        jointCount = std::max(jointCount, f.component + 1);
        break;
    }
  }
  const Mat3 R = (Eigen::AngleAxisd(rpy[0], Vec3::UnitX()) * Eigen::AngleAxisd(rpy[1], Vec3::UnitY()) *
                  Eigen::AngleAxisd(rpy[2], Vec3::UnitZ()))
                     .toRotationMatrix();
  if (!L.directFingertips) {
    const Vec3 centre = wrist + R * L.gripCentre_wrist;
    const Vec3 half = R.col(1) * (0.5 * grip);
    index = centre + half;
    thumb = centre - half;
  }
  sample.hand.index = index;
  sample.hand.thumb = thumb;
  for (int k = 2; k < grasp::HandSample::kMaxFingertips; ++k) sample.hand.fingertip(k) = extra[k];
  sample.hand.wrist = wrist;
  sample.hand.wristRotation = R;
  sample.buttons = buttons;
  sample.jointCount = jointCount;
  for (int i = 0; i < DeviceSample::kMaxJoints; ++i) sample.joints[i] = joints[i];
  return true;
}

DeviceCommand saturateCommand(const DeviceCommand& command, const DeviceSpec& spec) noexcept {
  DeviceCommand out;
  out.f_index = limitNorm(command.f_index, spec.maxForce_N);
  out.f_thumb = limitNorm(command.f_thumb, spec.maxForce_N);
  out.f_wrist = limitNorm(command.f_wrist, spec.maxForce_N);
  out.m_wrist = limitNorm(command.m_wrist, spec.maxTorque_Nm);
  out.f_grasp = std::isfinite(command.f_grasp) ? std::clamp(command.f_grasp, -spec.maxForce_N, spec.maxForce_N) : 0.0;
  for (int k = 2; k < grasp::HandSample::kMaxFingertips; ++k)
    out.fingertipForce(k) = limitNorm(command.fingertipForce(k), spec.maxForce_N);
  return out;
}

std::size_t encodeForceReport(const HidLayout& L, const DeviceCommand& command, std::uint8_t* out,
                              std::size_t capacity) noexcept {
  if (!L.force_output || !out) return 0;
  const auto& fo = *L.force_output;
  const auto size = static_cast<std::size_t>(fo.size);
  if (capacity < size) return 0;
  std::memset(out, 0, size);
  out[0] = static_cast<std::uint8_t>(fo.report_id);
  DeviceCommand c = command;
  for (const auto& f : fo.fields) {
    const Vec3* v = commandVector(c, f);
    const double value = v ? (*v)[f.component] : c.f_grasp;
    encodeHidValue((value - f.bias) / f.scale, out + f.offset, f.type, f.endian);
  }
  return size;
}

DeviceCommand decodeForceReport(const HidLayout& L, const std::uint8_t* data, std::size_t size) noexcept {
  DeviceCommand c;
  if (!L.force_output || !data || size < static_cast<std::size_t>(L.force_output->size)) return c;
  for (const auto& f : L.force_output->fields) {
    const double value = decodeHidValue(data + f.offset, f.type, f.endian) * f.scale + f.bias;
    if (Vec3* v = commandVector(c, f)) (*v)[f.component] = value;
    else c.f_grasp = value;
  }
  return c;
}

// ---- the device ---------------------------------------------------------------------

GenericHidDevice::GenericHidDevice(std::unique_ptr<HidConnection> connection, HidLayout layout)
    : connection_(std::move(connection)), layout_(std::move(layout)) {
  if (!connection_) throw HidError("GenericHidDevice: no connection");
}

bool GenericHidDevice::read(DeviceSample& sample) noexcept { return readAt(sample, monotonicSeconds()); }

bool GenericHidDevice::readAt(DeviceSample& sample, double now_s) noexcept {
  const auto want = static_cast<std::size_t>(layout_.report_size);
  bool got = false;
  for (int i = 0; i < kMaxReportsPerRead; ++i) {
    // One byte more than the layout's size, so an oversized report shows as such.
    const int n = connection_->read(in_.data(), want + 1, 0);
    if (n == 0) break;
    if (n < 0) {
      ++stats_.readErrors;
      break;
    }
    const auto size = static_cast<std::size_t>(n);
    if (layout_.input_report_id != 0 && in_[0] != layout_.input_report_id) {
      ++stats_.otherReports;
      continue;
    }
    if (size < want) {
      ++stats_.short_;
      continue;
    }
    if (size > want) {
      ++stats_.oversized;
      continue;
    }
    if (decodeInputReport(layout_, in_.data(), size, sample)) {
      ++stats_.accepted;
      got = true;
    }
  }
  if (got) {
    sample.hand.t = now_s;
    sample.deviceTime_s = now_s;
    lastInput_s_ = now_s;
  }
  return got;
}

void GenericHidDevice::write(const DeviceCommand& command) noexcept { writeAt(command, monotonicSeconds()); }

void GenericHidDevice::writeAt(const DeviceCommand& command, double now_s) noexcept {
  if (!layout_.force_output) return;
  DeviceCommand c;  // zero unless the input is alive
  if (now_s - lastInput_s_ <= layout_.watchdog_ms / 1000.0) {
    c = saturateCommand(command, layout_.spec);
  } else {
    ++stats_.watchdogZeroed;
  }
  const std::size_t n = encodeForceReport(layout_, c, out_.data(), out_.size());
  if (n == 0) return;
  ++stats_.writes;
  if (connection_->write(out_.data(), n) < 0) ++stats_.writeErrors;
}

}  // namespace hg::device
