#include "hapticgrasp/geometry/model_cache.hpp"

#include <BinTools.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include <unistd.h>

#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::geometry {
namespace {

constexpr char kMagic[8] = {'H', 'G', 'M', 'O', 'D', 'E', 'L', '1'};

std::uint64_t fnv1a(std::string_view bytes, std::uint64_t seed) {
  std::uint64_t h = seed;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}
constexpr std::uint64_t kSeedA = 0xcbf29ce484222325ull;  // FNV's offset basis
constexpr std::uint64_t kSeedB = 0x84222325cbf29ce4ull;  // an independent second hash

std::string hex(std::uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
  return text;
}

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

void putU64(std::string& out, std::uint64_t v) {
  char b[8];
  std::memcpy(b, &v, 8);
  out.append(b, 8);
}
std::uint64_t getU64(std::string_view in, std::size_t at) {
  std::uint64_t v;
  std::memcpy(&v, in.data() + at, 8);
  return v;
}

}  // namespace

const char* toString(ModelCache::Source source) {
  switch (source) {
    case ModelCache::Source::Memory: return "memory";
    case ModelCache::Source::Disk: return "disk";
    case ModelCache::Source::Built: return "built";
    case ModelCache::Source::Rebuilt: return "rebuilt";
  }
  return "?";
}

ModelCache::ModelCache(Options options) : options_(std::move(options)) {}

std::filesystem::path ModelCache::defaultDir() {
  if (const char* dir = std::getenv("HAPTICGRASP_CACHE_DIR"); dir && *dir)
    return std::string(dir) == "off" ? std::filesystem::path() : std::filesystem::path(dir);
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "hapticgrasp" / "models";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".cache" / "hapticgrasp" / "models";
  return {};
}

ModelCache& ModelCache::shared() {
  static ModelCache cache(Options{defaultDir()});
  return cache;
}

std::string ModelCache::keyOf(std::string_view brep, LengthUnit unit, const PartModel::LoadOptions& o) const {
  const std::string settings = "format " + std::to_string(kFormat) + " unit " + std::to_string(metresPer(unit)) +
                               " crossings " + (o.checkSelfIntersection ? "on" : "off");
  return hex(fnv1a(brep, kSeedA) ^ fnv1a(settings, kSeedA)) + hex(fnv1a(brep, kSeedB)) + "-" +
         std::to_string(brep.size()) + "-" + hex(fnv1a(settings, kSeedB)).substr(0, 8);
}

std::filesystem::path ModelCache::entryPath(const std::string& key) const {
  return options_.dir.empty() ? std::filesystem::path() : options_.dir / (key + ".hgm");
}

PartModelPtr ModelCache::remembered(const std::string& key) {
  const auto found = index_.find(key);
  if (found == index_.end()) return nullptr;
  lru_.splice(lru_.begin(), lru_, found->second);
  return found->second->second;
}

void ModelCache::remember(const std::string& key, PartModelPtr part) {
  if (options_.memoryEntries == 0) return;
  if (remembered(key)) return;
  lru_.emplace_front(key, std::move(part));
  index_[key] = lru_.begin();
  while (lru_.size() > options_.memoryEntries) {
    index_.erase(lru_.back().first);
    lru_.pop_back();
  }
}

void ModelCache::clearMemory() {
  std::lock_guard lock(mutex_);
  lru_.clear();
  index_.clear();
}

PartModelPtr ModelCache::load(std::string_view brep, LengthUnit unit, const std::string& name,
                              const PartModel::LoadOptions& options, Outcome* outcome) {
  Outcome local;
  Outcome& out = outcome ? *outcome : local;
  const std::string key = keyOf(brep, unit, options);
  const std::filesystem::path path = entryPath(key);
  {
    std::lock_guard lock(mutex_);
    if (PartModelPtr part = remembered(key)) {
      out = {Source::Memory, ""};
      return part;
    }
    std::error_code ec;
    if (!path.empty() && std::filesystem::exists(path, ec)) {
      std::string why;
      if (PartModelPtr part = readEntry(path, name, why)) {
        std::filesystem::last_write_time(path, std::filesystem::file_time_type::clock::now(), ec);  // recently used
        remember(key, part);
        out = {Source::Disk, ""};
        return part;
      }
      std::filesystem::remove(path, ec);
      out = {Source::Rebuilt, why};
    }
  }
  PartModelPtr part = PartModel::fromBrepText(brep, unit, name, options);  // outside the lock: slow
  std::lock_guard lock(mutex_);
  remember(key, part);
  if (!path.empty()) {
    try {
      writeEntry(path, *part);
      trimDisk();
    } catch (const std::exception&) {  // a full or read-only disk: the part is fine without
    }
  }
  if (out.source != Source::Rebuilt) out = {Source::Built, ""};
  return part;
}

PartModelPtr ModelCache::readEntry(const std::filesystem::path& path, const std::string& name, std::string& why) const {
  std::ifstream in(path, std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (bytes.size() < 24 || std::memcmp(bytes.data(), kMagic, 8) != 0) {
    why = "not a model cache entry";
    return nullptr;
  }
  const std::uint64_t size = getU64(bytes, 8), checksum = getU64(bytes, 16);
  const std::string_view payload = std::string_view(bytes).substr(24);
  if (payload.size() != size || fnv1a(payload, kSeedA) != checksum) {
    why = "checksum mismatch";
    return nullptr;
  }
  try {
    OCC_CATCH_SIGNALS  // a fault reading the entry rebuilds the part (occt_faults.hpp)
    if (payload.size() < 8) throw GeometryError("short payload");
    const std::uint64_t jsonSize = getU64(payload, 0);
    if (jsonSize > payload.size() - 8) throw GeometryError("bad record size");
    const PartModel::Record record = recordFrom(nlohmann::json::parse(payload.substr(8, jsonSize)));
    std::istringstream shapeStream(std::string(payload.substr(8 + jsonSize)));
    TopoDS_Shape shape;
    BinTools::Read(shape, shapeStream);
    if (shape.IsNull()) throw GeometryError("empty shape");
    return PartModel::restore(shape, record, name);
  } catch (const Standard_Failure& e) {
    why = std::string("unreadable shape: ") + e.GetMessageString();
  } catch (const std::exception& e) {
    why = std::string("unreadable entry: ") + e.what();
  }
  return nullptr;
}

void ModelCache::writeEntry(const std::filesystem::path& path, const PartModel& part) const {
  std::filesystem::create_directories(path.parent_path());
  const std::string json = recordJson(part.record()).dump();
  std::ostringstream shapeStream;
  BinTools::Write(part.shape(), shapeStream);
  std::string payload;
  putU64(payload, json.size());
  payload += json;
  payload += shapeStream.str();
  std::string bytes(kMagic, 8);
  putU64(bytes, payload.size());
  putU64(bytes, fnv1a(payload, kSeedA));
  bytes += payload;
  // Written aside and renamed: a reader never sees half an entry, a crash leaves none.
  const std::filesystem::path temporary =
      path.string() + ".tmp" + std::to_string(getpid()) + "-" + std::to_string(reinterpret_cast<std::uintptr_t>(&part));
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw std::runtime_error("cannot write " + temporary.string());
  }
  std::filesystem::rename(temporary, path);
}

std::uintmax_t ModelCache::diskBytes() const {
  std::uintmax_t total = 0;
  std::error_code ec;
  if (options_.dir.empty() || !std::filesystem::is_directory(options_.dir, ec)) return 0;
  for (const auto& e : std::filesystem::directory_iterator(options_.dir, ec))
    if (e.path().extension() == ".hgm") total += e.file_size(ec);
  return total;
}

void ModelCache::trimDisk() const {
  std::error_code ec;
  std::vector<std::pair<std::filesystem::file_time_type, std::filesystem::directory_entry>> entries;
  std::uintmax_t total = 0;
  for (const auto& e : std::filesystem::directory_iterator(options_.dir, ec)) {
    if (e.path().extension() != ".hgm") continue;
    entries.emplace_back(e.last_write_time(ec), e);
    total += e.file_size(ec);
  }
  if (total <= options_.maxBytes) return;
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [time, e] : entries) {
    if (total <= options_.maxBytes) break;
    total -= e.file_size(ec);
    std::filesystem::remove(e.path(), ec);
  }
}

}  // namespace hg::geometry
