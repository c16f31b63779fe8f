#pragma once
// A checked part model as bytes: the model cache's entry on disk (model_cache.hpp) and the
// loader process's answer (loader_process.hpp). It holds the checked (possibly healed) shape
// in OCCT's binary format and the load's record (PartModel::Record), so that restoring the
// part skips the validity and crossing checks, the healing and the mass integrals.
//
// Layout: the magic "HGMODEL1", the payload's size and its checksum (FNV-1a 64), then the
// payload: the record's JSON size, the record (nlohmann-json) and BinTools' shape stream.
// Hand-written: no Debian library serialises an OCCT shape with its checks' results.
#include <string>
#include <string_view>

#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::geometry {

std::string entryBytes(const PartModel& part);

// The part `bytes` hold, named `name`; nullptr with `why` for bytes that are not an entry,
// fail their checksum, or hold an unreadable record or shape (a fault while reading the shape
// too: OCC_CATCH_SIGNALS). `timing`, when given, is the load that made the entry (the loader
// process's), reported by the part as its own.
PartModelPtr partFromEntry(std::string_view bytes, const std::string& name, std::string& why,
                           const PartLoadTiming* timing = nullptr);

// FNV-1a 64 of `bytes` from `seed` (the entry's checksum; the cache's keys hash with two seeds).
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t seed);
constexpr std::uint64_t kFnvSeedA = 0xcbf29ce484222325ull;  // FNV's offset basis
constexpr std::uint64_t kFnvSeedB = 0x84222325cbf29ce4ull;  // an independent second hash

}  // namespace hg::geometry
