#include "hapticgrasp/session/mcap_format.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>

namespace hg::session {

std::string mcapOpName(std::uint8_t op) {
  static constexpr std::array<const char*, 16> names = {
      nullptr,      "header",           "footer",
      "schema",     "channel",          "message",
      "chunk",      "message index",    "chunk index",
      "attachment", "attachment index", "statistics",
      "metadata",   "metadata index",   "summary offset",
      "data end"};
  if (op > 0 && op < names.size()) return names[op];
  char text[24];
  std::snprintf(text, sizeof text, "opcode 0x%02x", op);
  return text;
}

std::uint32_t mcapCrc32(std::string_view bytes, std::uint32_t crc) {
  // zlib's length is a uInt: feed large buffers in pieces.
  const auto* p = reinterpret_cast<const Bytef*>(bytes.data());
  std::size_t left = bytes.size();
  uLong value = crc;
  while (left > 0) {
    const auto n = static_cast<uInt>(std::min<std::size_t>(left, 1u << 30));
    value = ::crc32(value, p, n);
    p += n;
    left -= n;
  }
  return static_cast<std::uint32_t>(value);
}

namespace mcap {

void putString(std::string& out, std::string_view s) {
  if (s.size() > std::numeric_limits<std::uint32_t>::max())
    throw McapError("MCAP string or byte field over 4 GiB");
  putU32(out, static_cast<std::uint32_t>(s.size()));
  out.append(s);
}

void putStringMap(std::string& out, const std::map<std::string, std::string>& map) {
  const std::size_t at = out.size();
  putU32(out, 0);
  for (const auto& [key, value] : map) {
    putString(out, key);
    putString(out, value);
  }
  const std::uint64_t bytes = out.size() - at - 4;
  if (bytes > std::numeric_limits<std::uint32_t>::max()) throw McapError("MCAP map over 4 GiB");
  for (int i = 0; i < 4; ++i) out[at + i] = static_cast<char>(bytes >> (8 * i));
}

void patchU64(std::string& out, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out[at + i] = static_cast<char>(v >> (8 * i));
}

std::size_t beginRecord(std::string& out, McapOp op) {
  const std::size_t start = out.size();
  putU8(out, static_cast<std::uint8_t>(op));
  putU64(out, 0);
  return start;
}

void endRecord(std::string& out, std::size_t start) {
  patchU64(out, start + 1, out.size() - start - kMcapRecordPrefix);
}

std::string_view FieldReader::bytes(std::uint64_t n) {
  if (n > left()) shortRecord(n);
  const std::string_view v = data_.substr(at_, n);
  at_ += n;
  return v;
}

std::map<std::string, std::string> FieldReader::stringMap() {
  FieldReader entries(bytes(u32()), what_);
  std::map<std::string, std::string> map;
  while (entries.left() > 0) {
    std::string key(entries.string());
    map[std::move(key)] = std::string(entries.string());
  }
  return map;
}

std::uint64_t FieldReader::take(int n) {
  if (static_cast<std::size_t>(n) > left()) shortRecord(n);
  const std::uint64_t v = getLE(data_.data() + at_, n);
  at_ += n;
  return v;
}

void FieldReader::shortRecord(std::uint64_t wanted) const {
  throw McapError(std::string(what_) + " record is shorter than its fields (a field of " +
                  std::to_string(wanted) + " bytes at offset " + std::to_string(at_) + ", " +
                  std::to_string(left()) + " left)");
}

}  // namespace mcap
}  // namespace hg::session
