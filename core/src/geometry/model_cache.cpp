#include "hapticgrasp/geometry/model_cache.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <vector>

#include <unistd.h>

#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/model_entry.hpp"

namespace hg::geometry {
namespace {

std::string hex(std::uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
  return text;
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
  return hex(fnv1a(brep, kFnvSeedA) ^ fnv1a(settings, kFnvSeedA)) + hex(fnv1a(brep, kFnvSeedB)) + "-" +
         std::to_string(brep.size()) + "-" + hex(fnv1a(settings, kFnvSeedB)).substr(0, 8);
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
                              const PartModel::LoadOptions& options, Outcome* outcome, const Build& build) {
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
  // Outside the lock: slow.
  PartModelPtr part = build ? build(brep, unit, name, options) : PartModel::fromBrepText(brep, unit, name, options);
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
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return partFromEntry(bytes, name, why);
}

void ModelCache::writeEntry(const std::filesystem::path& path, const PartModel& part) const {
  std::filesystem::create_directories(path.parent_path());
  const std::string bytes = entryBytes(part);
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
