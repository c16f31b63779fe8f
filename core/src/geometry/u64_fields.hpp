#pragma once
// The 8-byte sizes and checksums of the byte formats written here (model_entry.cpp,
// loader_process.cpp): host order, read back by the same build on the same machine (a
// cache entry, a helper's answer), never exchanged between machines.
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace hg::geometry {

inline void putU64(std::string& out, std::uint64_t v) {
  char b[8];
  std::memcpy(b, &v, 8);
  out.append(b, 8);
}

// The 8 bytes at `at`; the caller has checked that they are there.
inline std::uint64_t getU64(std::string_view in, std::size_t at) {
  std::uint64_t v;
  std::memcpy(&v, in.data() + at, 8);
  return v;
}

}  // namespace hg::geometry
