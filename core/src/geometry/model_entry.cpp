#include "hapticgrasp/geometry/model_entry.hpp"

#include <BinTools.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>

#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>

#include "geometry/u64_fields.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::geometry {
namespace {

constexpr char kMagic[8] = {'H', 'G', 'M', 'O', 'D', 'E', 'L', '1'};

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
Vec3 vec(const nlohmann::json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

nlohmann::json recordJson(const PartModel::Record& r) {
  nlohmann::json inertia = nlohmann::json::array();
  for (int i = 0; i < 9; ++i) inertia.push_back(r.unitDensityInertia(i / 3, i % 3));
  return {{"metres_per_unit", r.metresPerUnit},
          {"bounds", {vec(r.bounds.min), vec(r.bounds.max)}},
          {"volume_m3", r.volume_m3},
          {"centre_m", vec(r.centre_m)},
          {"unit_density_inertia", inertia},
          {"warnings", r.warnings},
          {"backend", std::string(toString(r.choice.backend))},
          {"reason", r.choice.reason},
          {"surface_may_cross", r.choice.surfaceMayCross}};
}

PartModel::Record recordFrom(const nlohmann::json& j) {
  PartModel::Record r;
  r.metresPerUnit = j.at("metres_per_unit").get<double>();
  r.bounds = {vec(j.at("bounds").at(0)), vec(j.at("bounds").at(1))};
  r.volume_m3 = j.at("volume_m3").get<double>();
  r.centre_m = vec(j.at("centre_m"));
  for (int i = 0; i < 9; ++i) r.unitDensityInertia(i / 3, i % 3) = j.at("unit_density_inertia").at(i).get<double>();
  r.warnings = j.at("warnings").get<std::vector<std::string>>();
  r.choice.backend = parseBackend(j.at("backend").get<std::string>());
  r.choice.reason = j.at("reason").get<std::string>();
  r.choice.surfaceMayCross = j.at("surface_may_cross").get<bool>();
  if (!(r.metresPerUnit > 0) || r.bounds.empty() || !(r.volume_m3 > 0)) throw GeometryError("implausible record");
  return r;
}

}  // namespace

std::uint64_t fnv1a(std::string_view bytes, std::uint64_t seed) {
  std::uint64_t h = seed;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

std::string entryBytes(const PartModel& part) {
  const std::string json = recordJson(part.record()).dump();
  std::ostringstream shapeStream;
  BinTools::Write(part.shape(), shapeStream);
  std::string payload;
  putU64(payload, json.size());
  payload += json;
  payload += shapeStream.str();
  std::string bytes(kMagic, 8);
  putU64(bytes, payload.size());
  putU64(bytes, fnv1a(payload, kFnvSeedA));
  bytes += payload;
  return bytes;
}

PartModelPtr partFromEntry(std::string_view bytes, const std::string& name, std::string& why,
                           const PartLoadTiming* timing) {
  if (bytes.size() < 24 || std::memcmp(bytes.data(), kMagic, 8) != 0) {
    why = "not a model cache entry";
    return nullptr;
  }
  const std::uint64_t size = getU64(bytes, 8), checksum = getU64(bytes, 16);
  const std::string_view payload = bytes.substr(24);
  if (payload.size() != size || fnv1a(payload, kFnvSeedA) != checksum) {
    why = "checksum mismatch";
    return nullptr;
  }
  try {
    OCC_CATCH_SIGNALS  // a fault reading the entry is a bad entry (occt_faults.hpp)
    if (payload.size() < 8) throw GeometryError("short payload");
    const std::uint64_t jsonSize = getU64(payload, 0);
    if (jsonSize > payload.size() - 8) throw GeometryError("bad record size");
    const PartModel::Record record = recordFrom(nlohmann::json::parse(payload.substr(8, jsonSize)));
    std::istringstream shapeStream(std::string(payload.substr(8 + jsonSize)));
    TopoDS_Shape shape;
    BinTools::Read(shape, shapeStream);
    if (shape.IsNull()) throw GeometryError("empty shape");
    return PartModel::restore(shape, record, name, timing);
  } catch (const Standard_Failure& e) {
    why = std::string("unreadable shape: ") + e.GetMessageString();
  } catch (const std::exception& e) {
    why = std::string("unreadable entry: ") + e.what();
  }
  return nullptr;
}

}  // namespace hg::geometry
