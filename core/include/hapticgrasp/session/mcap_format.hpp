#pragma once
// The MCAP container format (the public MCAP specification, major version 0): magic,
// record opcodes, little-endian field helpers, CRC-32 and the error type shared by
// McapWriter and McapReader.
//
// Hand-written because Debian 12 packages no MCAP library (no libmcap, no python3-mcap);
// the format is small: every record is `opcode u8, content length u64 LE, content`.
// Strings are `u32 length + bytes`, maps and arrays `u32 byte length + entries`, times
// u64 nanoseconds. tests/mcap/ checks our files with the reference reader (@mcap/core).
#include <cstddef>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>

namespace hg::session {

// Every failure of the writer and every refusal of the reader (no file, not MCAP).
class McapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// At the start and at the end of every MCAP file; the 0x30 is the major version "0".
inline constexpr std::string_view kMcapMagic{"\x89MCAP0\r\n", 8};

enum class McapOp : std::uint8_t {
  Header = 0x01,
  Footer = 0x02,
  Schema = 0x03,
  Channel = 0x04,
  Message = 0x05,
  Chunk = 0x06,
  MessageIndex = 0x07,
  ChunkIndex = 0x08,
  Attachment = 0x09,
  AttachmentIndex = 0x0A,
  Statistics = 0x0B,
  Metadata = 0x0C,
  MetadataIndex = 0x0D,
  SummaryOffset = 0x0E,
  DataEnd = 0x0F,
};

// "chunk", "message index", ... for messages; "opcode 0x42" for unknown ones.
std::string mcapOpName(std::uint8_t op);

// Bytes before a record's content: the opcode and the u64 content length.
inline constexpr std::size_t kMcapRecordPrefix = 9;
// The Footer record (prefix + summary_start, summary_offset_start, summary_crc) and the
// trailing magic: the fixed 37 bytes at the end of a finished file.
inline constexpr std::size_t kMcapFooterRecord = kMcapRecordPrefix + 20;
inline constexpr std::size_t kMcapTail = kMcapFooterRecord + kMcapMagic.size();
// The DataEnd record (prefix + data_section_crc) that sits right before the summary.
inline constexpr std::size_t kMcapDataEndRecord = kMcapRecordPrefix + 4;

// CRC-32 (zlib's crc32(), polynomial 0xEDB88320) as MCAP uses it; chain by passing the
// previous value as `crc`.
std::uint32_t mcapCrc32(std::string_view bytes, std::uint32_t crc = 0);

namespace mcap {

// Appending fields to a byte buffer, little-endian whatever the host.
inline void putU8(std::string& out, std::uint8_t v) { out.push_back(static_cast<char>(v)); }
inline void putU16(std::string& out, std::uint16_t v) {
  for (int i = 0; i < 2; ++i) out.push_back(static_cast<char>(v >> (8 * i)));
}
inline void putU32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>(v >> (8 * i)));
}
inline void putU64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>(v >> (8 * i)));
}
// A u32-length-prefixed string or byte field (throws McapError past 4 GiB).
void putString(std::string& out, std::string_view s);
// Map<string, string>: u32 byte length, then key and value strings.
void putStringMap(std::string& out, const std::map<std::string, std::string>& map);

// Overwrites a u64 already in `out` at `at` (record lengths known only once written).
void patchU64(std::string& out, std::size_t at, std::uint64_t v);
// Starts a record (opcode + placeholder length) and returns where it starts; endRecord
// sets its length from what was appended since.
std::size_t beginRecord(std::string& out, McapOp op);
void endRecord(std::string& out, std::size_t start);

// Little-endian decoding without bounds checks (the caller has checked the size).
inline std::uint64_t getLE(const char* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

// Reads fields from one record's content. Every read is bounds-checked: a field past the
// end throws McapError("<what>: ... shorter than its fields"), which readers turn into a
// warning about that record. Views point into the content; they live as long as it does.
class FieldReader {
 public:
  FieldReader(std::string_view content, std::string_view what) : data_(content), what_(what) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(take(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(take(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(take(4)); }
  std::uint64_t u64() { return take(8); }
  std::string_view bytes(std::uint64_t n);
  std::string_view string() { return bytes(u32()); }
  std::map<std::string, std::string> stringMap();
  std::string_view rest() { return bytes(left()); }
  std::size_t left() const { return data_.size() - at_; }
  std::size_t offset() const { return at_; }

 private:
  std::uint64_t take(int n);
  [[noreturn]] void shortRecord(std::uint64_t wanted) const;
  std::string_view data_;
  std::string_view what_;
  std::size_t at_ = 0;
};

}  // namespace mcap
}  // namespace hg::session
