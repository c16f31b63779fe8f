#pragma once
// Nothing built twice: checked part models kept in memory (a second Start in the same
// process) and on disk under the XDG cache folder (the next FreeCAD session, another
// document with parts seen before).
//
// Key: the shape's content (its BREP text, hashed: two independent 64-bit FNV-1a hashes
// and the text's length), the unit, the load options, and kFormat, the version of what a
// load computes; a change to any of them misses. An entry holds the checked (possibly
// healed) shape in OCCT's binary format and the load's record (PartModel::Record): a hit
// skips the validity and crossing checks, the healing and the mass integrals, and costs a
// binary read. Entries are checksummed (FNV-1a 64 over the payload); a corrupt or
// unreadable entry is deleted, the part built again and the entry rewritten: never
// trusted. The disk holds at most maxBytes: the least recently used entries go first.
//
// Hand-written: no Debian library caches OCCT shapes; an entry's format: model_entry.hpp.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <list>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>

#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::geometry {

class ModelCache {
 public:
  static constexpr int kFormat = 1;  // bump when PartModel's load computes something else

  struct Options {
    std::filesystem::path dir;                     // empty: no disk cache
    std::uintmax_t maxBytes = 2ull << 30;          // disk budget
    std::size_t memoryEntries = 256;               // parts kept in memory
  };
  // Where a load came from.
  enum class Source { Memory, Disk, Built, Rebuilt };
  struct Outcome {
    Source source = Source::Built;
    std::string note;  // Rebuilt: why the entry was not trusted
  };

  explicit ModelCache(Options options);
  // The process's cache: $XDG_CACHE_HOME/hapticgrasp/models (else ~/.cache/...), or
  // $HAPTICGRASP_CACHE_DIR; "off" there turns the disk cache off.
  static ModelCache& shared();
  static std::filesystem::path defaultDir();

  // How a part the cache does not hold is loaded: PartModel::fromBrepText in this process
  // when empty; in FreeCAD, the loader process (loader_process.hpp).
  using Build = std::function<PartModelPtr(std::string_view brep, LengthUnit unit, const std::string& name,
                                           const PartModel::LoadOptions& options)>;

  // The part BREP text `brep` describes (in `unit`), checked: from memory, the disk, or
  // loaded (by `build`) and stored. Throws what the load throws; a part that cannot be
  // loaded is not cached.
  PartModelPtr load(std::string_view brep, LengthUnit unit, const std::string& name,
                    const PartModel::LoadOptions& options = {}, Outcome* outcome = nullptr, const Build& build = {});

  std::string keyOf(std::string_view brep, LengthUnit unit, const PartModel::LoadOptions& options) const;
  std::filesystem::path entryPath(const std::string& key) const;
  std::uintmax_t diskBytes() const;
  void clearMemory();

 private:
  PartModelPtr readEntry(const std::filesystem::path& path, const std::string& name, std::string& why) const;
  void writeEntry(const std::filesystem::path& path, const PartModel& part) const;
  void trimDisk() const;
  PartModelPtr remembered(const std::string& key);
  void remember(const std::string& key, PartModelPtr part);

  Options options_;
  mutable std::mutex mutex_;  // the memory map and the disk's files
  std::list<std::pair<std::string, PartModelPtr>> lru_;  // most recent first
  std::unordered_map<std::string, std::list<std::pair<std::string, PartModelPtr>>::iterator> index_;
};

const char* toString(ModelCache::Source source);  // "memory", "disk", "built", "rebuilt"

}  // namespace hg::geometry
