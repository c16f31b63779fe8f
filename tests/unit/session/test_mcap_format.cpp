// The MCAP field helpers: the CRC is the standard CRC-32, fields are little-endian with the
// specification's length prefixes, and reading past a record's end throws, never reads on.
#include "hapticgrasp/session/mcap_format.hpp"

#include <gtest/gtest.h>

namespace hg::session {
namespace {

using namespace mcap;

TEST(McapFormat, Crc32IsTheStandardOneAndChains) {
  EXPECT_EQ(mcapCrc32("123456789"), 0xCBF43926u);  // the CRC-32 check value
  EXPECT_EQ(mcapCrc32(""), 0u);
  EXPECT_EQ(mcapCrc32("6789", mcapCrc32("12345")), 0xCBF43926u);
}

TEST(McapFormat, FieldsAreLittleEndianWithLengthPrefixes) {
  std::string out;
  putU16(out, 0x0102);
  putU32(out, 0x03040506);
  putU64(out, 0x0708090A0B0C0D0Eull);
  putString(out, "ab");
  putStringMap(out, {{"k", "v"}});
  const std::string expected(
      "\x02\x01\x06\x05\x04\x03\x0E\x0D\x0C\x0B\x0A\x09\x08\x07"
      "\x02\0\0\0ab"
      "\x0A\0\0\0\x01\0\0\0k\x01\0\0\0v",
      14 + 6 + 14);
  EXPECT_EQ(out, expected);

  FieldReader r(out, "test");
  EXPECT_EQ(r.u16(), 0x0102);
  EXPECT_EQ(r.u32(), 0x03040506u);
  EXPECT_EQ(r.u64(), 0x0708090A0B0C0D0Eull);
  EXPECT_EQ(r.string(), "ab");
  EXPECT_EQ(r.stringMap(), (std::map<std::string, std::string>{{"k", "v"}}));
  EXPECT_EQ(r.left(), 0u);
}

TEST(McapFormat, RecordsCarryTheirContentLength) {
  std::string out = "xx";
  const std::size_t start = beginRecord(out, McapOp::Metadata);
  putString(out, "abc");
  endRecord(out, start);
  ASSERT_EQ(out.size(), 2u + kMcapRecordPrefix + 7);
  EXPECT_EQ(out[2], '\x0C');
  EXPECT_EQ(getLE(out.data() + 3, 8), 7u);
}

TEST(McapFormat, ReadingPastTheEndThrowsAClearError) {
  std::string out;
  putU32(out, 1000);  // a string that claims 1000 bytes
  out += "short";
  FieldReader r(out, "schema");
  try {
    r.string();
    FAIL();
  } catch (const McapError& e) {
    EXPECT_STREQ(
        e.what(),
        "schema record is shorter than its fields (a field of 1000 bytes at offset 4, 5 left)");
  }
  FieldReader empty("", "channel");
  EXPECT_THROW(empty.u16(), McapError);
  std::string map;
  putU32(map, 3);  // a map whose entries are cut inside
  map += "\x05\0\0";
  FieldReader m(map, "metadata");
  EXPECT_THROW(m.stringMap(), McapError);
}

TEST(McapFormat, NamesOpcodes) {
  EXPECT_EQ(mcapOpName(0x06), "chunk");
  EXPECT_EQ(mcapOpName(0x0F), "data end");
  EXPECT_EQ(mcapOpName(0x42), "opcode 0x42");
  EXPECT_EQ(mcapOpName(0x00), "opcode 0x00");
}

}  // namespace
}  // namespace hg::session
