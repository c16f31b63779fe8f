// The MCAP reader on files cut short, damaged and hostile: it reads what is intact, says
// what it lost, and never crashes, hangs or takes memory a file only claims to need. Also
// the time-window read through the summary's chunk index.
#include "hapticgrasp/session/mcap_reader.hpp"

#include <gtest/gtest.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <random>

#include "alloc_counter.hpp"
#include "session/mcap_fixtures.hpp"

namespace hg::session {
namespace {

using namespace test;
using namespace mcap;

constexpr std::uint64_t kMiB = 1 << 20;

bool contains(const std::vector<std::string>& warnings, const std::string& text) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

std::string joined(const std::vector<std::string>& warnings) {
  std::string s;
  for (const auto& w : warnings) s += "\n  " + w;
  return s;
}

// Messages of the sample that lie in a chunk (by its time range).
std::uint64_t messagesIn(const Sample& sample, const McapChunkInfo& c) {
  return std::count_if(sample.messages.begin(), sample.messages.end(), [&](const SampleMessage& m) {
    return m.logTime_ns >= c.startTime_ns && m.logTime_ns <= c.endTime_ns;
  });
}

struct Read {
  McapSummary summary;
  std::vector<std::uint32_t> sequences;
  bool intact = true;  // every message delivered is the one the sample wrote
};

Read readChecked(const std::string& path, const Sample& sample, McapReader::Limits limits = {}) {
  Read r;
  McapReader reader(path, limits);
  r.summary = reader.scan([&](const McapMessageView& m) {
    r.sequences.push_back(m.sequence);
    const bool known = m.sequence < sample.messages.size();
    r.intact = r.intact && known && sample.messages[m.sequence].data == m.data &&
               sample.messages[m.sequence].channel == m.channel &&
               sample.messages[m.sequence].logTime_ns == m.logTime_ns;
  });
  return r;
}

void patchFile(const std::string& path, std::uint64_t at, std::string_view bytes) {
  std::string file = readFile(path);
  file.replace(at, bytes.size(), bytes);
  writeFile(path, file);
}

std::string le64(std::uint64_t v) {
  std::string s;
  putU64(s, v);
  return s;
}

// ---- Hand-made records for hostile files.

std::string record(McapOp op, std::string_view content) {
  std::string r;
  putU8(r, static_cast<std::uint8_t>(op));
  putU64(r, content.size());
  r.append(content);
  return r;
}

std::string chunkRecord(std::uint64_t time, std::uint64_t uncompressed, std::uint32_t crc,
                        std::string_view compression, std::string_view payload) {
  std::string c;
  putU64(c, time);
  putU64(c, time);
  putU64(c, uncompressed);
  putU32(c, crc);
  putString(c, compression);
  putU64(c, payload.size());
  c.append(payload);
  return record(McapOp::Chunk, c);
}

// An uncompressed chunk defining channel 1 and holding one message at `time`.
std::string goodChunk(std::uint64_t time) {
  std::string channel, message;
  putU16(channel, 1);
  putU16(channel, 0);
  putString(channel, "/ok");
  putString(channel, "json");
  putU32(channel, 0);
  putU16(message, 1);
  putU32(message, 0);
  putU64(message, time);
  putU64(message, time);
  message += "{}";
  const std::string records = record(McapOp::Channel, channel) + record(McapOp::Message, message);
  return chunkRecord(time, records.size(), mcapCrc32(records), "", records);
}

// Magic, Header, the given records; no DataEnd, no summary (an unfinished file).
std::string unfinished(const std::vector<std::string>& records) {
  std::string file(kMcapMagic), header;
  putString(header, "");
  putString(header, "test");
  file += record(McapOp::Header, header);
  for (const auto& r : records) file += r;
  return file;
}

// A real zstd bomb: 1 GiB of zeros in one frame that declares its size honestly (or not at
// all), some tens of KiB compressed. Made by streaming, never holding the GiB.
std::string zeroBomb(std::uint64_t bytes, bool declareSize) {
  ZSTD_CCtx* c = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(c, ZSTD_c_compressionLevel, 1);
  if (declareSize) ZSTD_CCtx_setPledgedSrcSize(c, bytes);
  const std::string zeros(kMiB, '\0');
  std::string out, buffer(ZSTD_CStreamOutSize(), '\0');
  for (std::uint64_t done = 0; done < bytes; done += kMiB) {
    const bool last = done + kMiB >= bytes;
    ZSTD_inBuffer in{zeros.data(), zeros.size(), 0};
    for (std::size_t left = 1; last ? left != 0 : in.pos < in.size;) {
      ZSTD_outBuffer o{buffer.data(), buffer.size(), 0};
      left = ZSTD_compressStream2(c, &o, &in, last ? ZSTD_e_end : ZSTD_e_continue);
      out.append(buffer.data(), o.pos);
    }
  }
  ZSTD_freeCCtx(c);
  return out;
}

std::uint32_t zerosCrc(std::uint64_t bytes) {
  const std::string zeros(kMiB, '\0');
  std::uint32_t crc = 0;
  for (std::uint64_t done = 0; done < bytes; done += kMiB) crc = mcapCrc32(zeros, crc);
  return crc;
}

// ---- Opening.

TEST(McapReader, OpensOnlyMcapFiles) {
  TempDir dir;
  try {
    McapReader r(dir.file("missing.mcap"));
    FAIL();
  } catch (const McapError& e) {
    EXPECT_NE(
        std::string(e.what()).find("cannot open " + dir.file("missing.mcap") + ": No such file"),
        std::string::npos)
        << e.what();
  }
  writeFile(dir.file("text.mcap"), "hello, this is not MCAP at all\n");
  writeFile(dir.file("empty.mcap"), "");
  writeFile(dir.file("short.mcap"), kMcapMagic.substr(0, 5));
  for (const char* name : {"text.mcap", "empty.mcap", "short.mcap"}) {
    try {
      McapReader r(dir.file(name));
      FAIL() << name;
    } catch (const McapError& e) {
      EXPECT_NE(std::string(e.what()).find("is not an MCAP file"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(McapReader r(dir.file("")), McapError);  // the directory itself
}

// ---- Cut short.

// A recording killed at any byte reads its complete chunks, in order, and says it is not
// complete; only a cut inside the magic throws.
TEST(McapReader, TruncatedAnywhereReadsItsCompleteChunks) {
  TempDir dir;
  const std::string full = dir.file("full.mcap"), cut = dir.file("cut.mcap");
  McapWriter::Options options;
  options.chunkBytes = 8 << 10;
  const Sample sample = writeSample(full, 2000, options);
  const std::vector<McapChunkInfo> chunks = McapReader(full).chunkIndex();
  ASSERT_GE(chunks.size(), 20u);
  const std::string bytes = readFile(full);
  int cuts = 0, insideChunks = 0;
  for (std::uint64_t n = 0; n < bytes.size(); n += 337) {
    writeFile(cut, std::string_view(bytes).substr(0, n));
    if (n < kMcapMagic.size()) {
      EXPECT_THROW(McapReader r(cut), McapError);
      continue;
    }
    std::uint64_t expected = 0, lastTime = 0;
    bool inChunk = false;
    for (const McapChunkInfo& c : chunks) {
      if (c.offset + c.length <= n)
        expected += messagesIn(sample, c), lastTime = c.endTime_ns;
      else
        inChunk = inChunk || c.offset < n;
    }
    Read r;
    ASSERT_NO_THROW(r = readChecked(cut, sample)) << "cut at " << n;
    ++cuts;
    EXPECT_FALSE(r.summary.complete) << n;
    ASSERT_EQ(r.summary.messages, expected) << "cut at " << n << joined(r.summary.warnings);
    EXPECT_TRUE(r.intact) << n;
    for (std::uint32_t i = 0; i < r.sequences.size(); ++i) ASSERT_EQ(r.sequences[i], i) << n;
    EXPECT_EQ(r.summary.lastGoodTime_ns, lastTime) << n;
    EXPECT_LE(r.summary.bytesRecovered, n);
    EXPECT_EQ(r.summary.fileBytes, n);
    ASSERT_FALSE(r.summary.warnings.empty()) << n;
    EXPECT_NE(r.summary.warnings.back().find("the file ends"), std::string::npos)
        << r.summary.warnings.back();
    EXPECT_NE(
        r.summary.warnings.back().find(std::to_string(expected) + " messages recovered up to"),
        std::string::npos)
        << r.summary.warnings.back();
    if (inChunk) {
      ++insideChunks;
      EXPECT_NE(r.summary.warnings.back().find("the file ends inside a chunk at byte"),
                std::string::npos)
          << r.summary.warnings.back();
    }
  }
  EXPECT_GT(cuts, 300);
  EXPECT_GT(insideChunks, cuts / 2);
}

// ---- Damaged.

TEST(McapReader, ChunkWithABadCrcIsSkippedAndTheOthersRead) {
  TempDir dir;
  const std::string path = dir.file("crc.mcap");
  McapWriter::Options options;
  options.chunkBytes = 8 << 10;
  const Sample sample = writeSample(path, 2000, options);
  const std::vector<McapChunkInfo> chunks = McapReader(path).chunkIndex();
  const McapChunkInfo& bad = chunks[3];
  const std::uint64_t crcAt = bad.offset + kMcapRecordPrefix + 24;
  const std::string original = readFile(path).substr(crcAt, 4);
  std::string flipped = original;
  flipped[1] = static_cast<char>(flipped[1] ^ 0x10);
  patchFile(path, crcAt, flipped);

  const Read r = readChecked(path, sample);
  EXPECT_TRUE(r.summary.complete) << "the structure is intact";
  EXPECT_EQ(r.summary.messages, sample.messages.size() - messagesIn(sample, bad));
  EXPECT_EQ(r.summary.chunksSkipped, 1u);
  EXPECT_TRUE(r.intact);
  EXPECT_TRUE(contains(r.summary.warnings,
                       "chunk at byte " + std::to_string(bad.offset) + ": CRC mismatch; skipped"))
      << joined(r.summary.warnings);
  EXPECT_EQ(r.summary.lastGoodTime_ns, chunks[2].endTime_ns);
  EXPECT_EQ(r.summary.lastTime_ns, sample.messages.back().logTime_ns);
}

// Every chunk names its schemas and channels again: in a file cut short (no summary to
// name them), losing the first chunk loses nothing else.
TEST(McapReader, DamagedFirstChunkLosesOnlyItsOwnMessages) {
  TempDir dir;
  const std::string path = dir.file("first.mcap");
  McapWriter::Options options;
  options.chunkBytes = 8 << 10;
  const Sample sample = writeSample(path, 1000, options);
  const std::vector<McapChunkInfo> chunks = McapReader(path).chunkIndex();
  const McapChunkInfo first = chunks.front(), last = chunks.back();
  const std::string good = readFile(path).substr(0, last.offset + 10);
  const std::uint64_t kept =
      sample.messages.size() - messagesIn(sample, first) - messagesIn(sample, last);
  const std::uint64_t payload = first.offset + first.length - first.compressedBytes;
  int tried = 0;
  for (std::uint64_t at = payload; at < first.offset + first.length; at += 97, ++tried) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0x5A);
    writeFile(path, bad);
    const Read r = readChecked(path, sample);
    ASSERT_EQ(r.summary.messages, kept) << "byte " << at << joined(r.summary.warnings);
    EXPECT_TRUE(r.intact);
    EXPECT_EQ(r.summary.perChannel.size(), 3u) << "a channel was orphaned";
    EXPECT_TRUE(
        contains(r.summary.warnings, "chunk at byte " + std::to_string(first.offset) + ": "))
        << joined(r.summary.warnings);
  }
  EXPECT_GT(tried, 10);
}

// A length that runs past the end of the file: in a finished file, the rest is read
// through the summary's chunk index; in an unfinished one, the reading stops there.
TEST(McapReader, AbsurdRecordLengthStopsTheScanNotTheRead) {
  TempDir dir;
  const std::string path = dir.file("length.mcap");
  McapWriter::Options options;
  options.chunkBytes = 8 << 10;
  const Sample sample = writeSample(path, 2000, options);
  const std::string good = readFile(path);
  const std::vector<McapChunkInfo> chunks = McapReader(path).chunkIndex();
  const McapChunkInfo& bad = chunks[4];
  for (const std::uint64_t length : {std::uint64_t{1} << 62, bad.length - 9 - 100}) {
    patchFile(path, bad.offset + 1, le64(length));
    hg::test::resetLargestAllocation();
    const Read r = readChecked(path, sample);
    EXPECT_LT(hg::test::largestAllocation(), 4 * kMiB);
    EXPECT_FALSE(r.summary.complete);
    EXPECT_TRUE(r.intact);
    EXPECT_EQ(r.summary.messages, sample.messages.size() - messagesIn(sample, bad))
        << joined(r.summary.warnings);
    EXPECT_TRUE(contains(r.summary.warnings, "read through the summary's chunk index"))
        << joined(r.summary.warnings);
    EXPECT_EQ(r.summary.lastGoodTime_ns, chunks[3].endTime_ns);
    writeFile(path, good);
  }
  // Unfinished (no index): the chunks before it, and a clear word about why no more.
  std::string cut = good.substr(0, chunks[9].offset + 50);
  cut.replace(bad.offset + 1, 8, le64(std::uint64_t{1} << 62));
  writeFile(path, cut);
  const Read r = readChecked(path, sample);
  std::uint64_t expected = 0;
  for (int i = 0; i < 4; ++i) expected += messagesIn(sample, chunks[i]);
  EXPECT_EQ(r.summary.messages, expected);
  EXPECT_TRUE(contains(r.summary.warnings, "the file ends inside a chunk at byte " +
                                               std::to_string(bad.offset) +
                                               " (it declares 4611686018427387904 bytes"))
      << joined(r.summary.warnings);
}

TEST(McapReader, HugeDeclaredUncompressedSizeIsRefusedWithoutAllocating) {
  TempDir dir;
  const std::string path = dir.file("huge.mcap");
  McapWriter::Options options;
  options.chunkBytes = 8 << 10;
  const Sample sample = writeSample(path, 1000, options);
  const std::vector<McapChunkInfo> chunks = McapReader(path).chunkIndex();
  patchFile(path, chunks[1].offset + kMcapRecordPrefix + 16, le64(std::uint64_t{1} << 60));
  hg::test::resetLargestAllocation();
  const Read r = readChecked(path, sample);
  EXPECT_LT(hg::test::largestAllocation(), 4 * kMiB);
  EXPECT_EQ(r.summary.messages, sample.messages.size() - messagesIn(sample, chunks[1]));
  EXPECT_TRUE(
      contains(r.summary.warnings,
               "chunk at byte " + std::to_string(chunks[1].offset) +
                   ": it declares 1099511627776.0 MiB uncompressed, over the limit of 256.0 MiB"))
      << joined(r.summary.warnings);
}

// 1 GiB of zeros in ~40 KiB: refused by the size limit, by the ratio limit when the size
// limit allows it, and when the chunk understates it; the good chunk after it still reads.
TEST(McapReader, ZstdBombIsRefusedWithoutAllocatingIt) {
  constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;
  const std::string bomb = zeroBomb(kGiB, true);
  ASSERT_EQ(ZSTD_getFrameContentSize(bomb.data(), bomb.size()), kGiB);
  ASSERT_LT(bomb.size(), kMiB);
  const std::string unsized = zeroBomb(64 * kMiB, false);
  ASSERT_EQ(ZSTD_getFrameContentSize(unsized.data(), unsized.size()), ZSTD_CONTENTSIZE_UNKNOWN);
  TempDir dir;
  const std::string path = dir.file("bomb.mcap");
  const std::uint32_t crc = zerosCrc(kGiB);
  McapReader::Limits generous;
  generous.maxChunkUncompressed = 2 * kGiB;
  struct Case {
    std::string chunk;
    McapReader::Limits limits;
    std::string says;
  };
  const std::vector<Case> cases = {
      {chunkRecord(1, kGiB, crc, "zstd", bomb),
       {},
       "declares 1024.0 MiB uncompressed, over the limit of 256.0 MiB"},
      {chunkRecord(1, kGiB, crc, "zstd", bomb), generous,
       "a compression ratio over the limit of 1000:1"},
      {chunkRecord(1, kMiB, 0, "zstd", bomb),
       {},
       "its zstd frame holds 1073741824 bytes, more than the 1048576"},
      {chunkRecord(1, kMiB, 0, "zstd", unsized), {}, "zstd: Destination buffer is too small"},
      {chunkRecord(1, kMiB, 0, "lz4", unsized), {}, "compression 'lz4' is not supported"},
  };
  for (const Case& c : cases) {
    writeFile(path, unfinished({c.chunk, goodChunk(2)}));
    McapReader reader(path, c.limits);
    std::vector<std::uint64_t> times;
    hg::test::resetLargestAllocation();
    const McapSummary s =
        reader.scan([&](const McapMessageView& m) { times.push_back(m.logTime_ns); });
    EXPECT_LT(hg::test::largestAllocation(), 2 * kMiB) << c.says;
    EXPECT_EQ(times, std::vector<std::uint64_t>{2}) << c.says;
    EXPECT_EQ(s.chunksSkipped, 1u);
    EXPECT_TRUE(
        contains(s.warnings, "chunk at byte " + std::to_string(unfinished({}).size()) + ": "))
        << joined(s.warnings);
    EXPECT_TRUE(contains(s.warnings, c.says)) << joined(s.warnings);
  }
}

TEST(McapReader, GarbageNeverCrashesOrFloods) {
  TempDir dir;
  const std::string path = dir.file("garbage.mcap");
  std::mt19937_64 rng(11);
  for (int seed = 0; seed < 40; ++seed) {
    std::string file(kMcapMagic);
    const std::size_t n = std::uniform_int_distribution<std::size_t>(0, 200000)(rng);
    for (std::size_t i = 0; i < n; ++i) file.push_back(static_cast<char>(rng()));
    writeFile(path, file);
    McapSummary s;
    ASSERT_NO_THROW(s = McapReader(path).scan()) << seed;
    EXPECT_FALSE(s.complete);
    EXPECT_FALSE(s.warnings.empty());
  }
  // 100,000 unknown records: one warning each would flood; the list stops at 100, a note
  // that more were left out, and the word on where the read ended.
  std::vector<std::string> unknown(100000, record(static_cast<McapOp>(0x42), "x"));
  writeFile(path, unfinished(unknown));
  const McapSummary s = McapReader(path).scan();
  EXPECT_EQ(s.warnings.size(), 102u);
  EXPECT_EQ(s.warnings.back(), "the file ends at byte " + std::to_string(s.fileBytes) +
                                   " without its DataEnd record: 0 messages recovered up to 0.0 s")
      << "the last word is kept for the end";
}

// Any one flipped byte anywhere: no exception, and no message that differs from the one
// written is ever delivered (what is not covered by a CRC does not carry message data).
TEST(McapReader, AnyFlippedByteNeverDeliversAWrongMessage) {
  TempDir dir;
  const std::string path = dir.file("flip.mcap");
  McapWriter::Options options;
  options.chunkBytes = 4 << 10;
  const Sample sample = writeSample(path, 400, options);
  const std::string good = readFile(path);
  int damaged = 0;
  for (std::size_t at = 0; at < good.size(); at += 13) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0xA5);
    writeFile(path, bad);
    if (at < kMcapMagic.size()) {
      EXPECT_THROW(McapReader r(path), McapError);
      continue;
    }
    Read r;
    ASSERT_NO_THROW(r = readChecked(path, sample)) << at;
    ASSERT_TRUE(r.intact) << "byte " << at;
    EXPECT_LE(r.summary.messages, sample.messages.size());
    damaged += r.summary.messages < sample.messages.size();
    McapReader reader(path);
    EXPECT_NO_THROW(reader.readMessages(0, ~0ull, [](const McapMessageView&) {}));
  }
  EXPECT_GT(damaged, 100);
}

TEST(McapReader, DamagedSummaryFallsBackToTheLinearScan) {
  TempDir dir;
  const std::string path = dir.file("summary.mcap");
  const Sample sample = writeSample(path, 1000);
  std::string bytes = readFile(path);
  const std::uint64_t summaryStart = getLE(bytes.data() + bytes.size() - kMcapTail + 9, 8);
  bytes[summaryStart + 20] = static_cast<char>(bytes[summaryStart + 20] ^ 1);
  writeFile(path, bytes);
  McapReader reader(path);
  EXPECT_FALSE(reader.indexed());
  const Read r = readChecked(path, sample);
  EXPECT_FALSE(r.summary.complete);
  EXPECT_EQ(r.summary.messages, sample.messages.size());
  EXPECT_TRUE(
      contains(r.summary.warnings, "summary: CRC mismatch; the file is read without its index"))
      << joined(r.summary.warnings);
}

// ---- Attachments.

TEST(McapReader, AttachmentsWithoutDataOverTheLimitOrWithABadCrc) {
  TempDir dir;
  const std::string path = dir.file("attach.mcap");
  writeSample(path, 300);
  {
    McapReader reader(path);
    reader.scan({}, false);
    ASSERT_EQ(reader.attachments().size(), 1u);
    EXPECT_FALSE(reader.attachments()[0].dataLoaded);
    EXPECT_EQ(reader.attachments()[0].dataBytes, 5000u);
    EXPECT_EQ(reader.attachments()[0].name, "part.brep");
  }
  {
    McapReader::Limits limits;
    limits.maxAttachmentBytes = 4999;
    McapReader reader(path, limits);
    const McapSummary s = reader.scan();
    EXPECT_FALSE(reader.attachments().at(0).dataLoaded);
    EXPECT_TRUE(contains(s.warnings, "attachment 'part.brep' at byte ")) << joined(s.warnings);
    EXPECT_TRUE(contains(s.warnings, "over the limit")) << joined(s.warnings);
  }
  std::uint64_t offset = 0;
  {
    McapReader reader(path);
    EXPECT_EQ(reader.scan().messages, 300u);
    EXPECT_TRUE(reader.attachments().at(0).dataLoaded);
    offset = reader.attachments().at(0).offset;
  }
  std::string bytes = readFile(path);
  bytes[offset + 100] = static_cast<char>(bytes[offset + 100] ^ 1);
  writeFile(path, bytes);
  McapReader reader(path);
  const McapSummary s = reader.scan();
  EXPECT_EQ(s.messages, 300u);
  EXPECT_FALSE(reader.attachments().at(0).dataLoaded);
  EXPECT_TRUE(contains(
      s.warnings, "attachment 'part.brep' at byte " + std::to_string(offset) + ": CRC mismatch"))
      << joined(s.warnings);
}

// ---- Seeking by time.

TEST(McapReader, TimeWindowReturnsExactlyItsMessagesFromFewerChunks) {
  TempDir dir;
  const std::string path = dir.file("window.mcap");
  McapWriter::Options options;
  options.chunkBytes = 8 << 10;
  const std::uint64_t t0 = 5'000'000'000;
  const Sample sample = writeSample(path, 5000, options, t0);
  auto expect = [&](std::uint64_t a, std::uint64_t b, std::uint64_t upTo) {
    std::vector<std::uint32_t> s;
    for (const auto& m : sample.messages)
      if (m.logTime_ns >= a && m.logTime_ns <= b && m.sequence < upTo) s.push_back(m.sequence);
    return s;
  };
  McapReader reader(path);
  ASSERT_TRUE(reader.indexed());
  const std::uint64_t chunks = reader.chunkIndex().size();
  std::mt19937_64 rng(3);
  for (int k = 0; k < 30; ++k) {
    std::uint64_t a = t0 + rng() % 5'200'000'000, b = a + rng() % 800'000'000;
    if (k == 0) a = 0, b = ~0ull;
    if (k == 1) a = b = sample.messages[1234].logTime_ns;  // one instant, inclusive
    std::vector<std::uint32_t> got;
    const McapWindowRead w =
        reader.readMessages(a, b, [&](const McapMessageView& m) { got.push_back(m.sequence); });
    EXPECT_TRUE(w.indexed);
    EXPECT_EQ(got, expect(a, b, ~0u)) << a << ".." << b;
    EXPECT_EQ(w.messages, got.size());
    EXPECT_EQ(w.chunksInFile, chunks);
    std::uint64_t overlapping = 0;
    for (const McapChunkInfo& c : reader.chunkIndex())
      overlapping += c.endTime_ns >= a && c.startTime_ns <= b;
    EXPECT_EQ(w.chunksRead, overlapping);
    if (k > 0 && b - a < 500'000'000) {
      EXPECT_LT(w.chunksRead, chunks / 4);
    }
  }
  // Cut short, the same reads scan the file; they still skip chunks outside the window.
  const std::string bytes = readFile(path);
  const McapChunkInfo half = reader.chunkIndex()[chunks / 2];
  writeFile(path, std::string_view(bytes).substr(0, half.offset + 10));
  McapReader cut(path);
  EXPECT_FALSE(cut.indexed());
  const std::uint32_t recovered = static_cast<std::uint32_t>(
      std::count_if(sample.messages.begin(), sample.messages.end(),
                    [&](const auto& m) { return m.logTime_ns < half.startTime_ns; }));
  const std::uint64_t a = t0 + 1'000'000'000, b = t0 + 1'300'000'000;
  std::vector<std::uint32_t> got;
  const McapWindowRead w =
      cut.readMessages(a, b, [&](const McapMessageView& m) { got.push_back(m.sequence); });
  EXPECT_FALSE(w.indexed);
  EXPECT_EQ(got, expect(a, b, recovered));
  EXPECT_LT(w.chunksRead, chunks / 4);
  EXPECT_TRUE(contains(w.warnings, "the file ends inside a chunk")) << joined(w.warnings);
}

// ---- Larger than one chunk by far, in bounded memory.

TEST(McapReader, StreamsAFileInChunkSizedMemory) {
  TempDir dir;
  const std::string path = dir.file("big.mcap");
  std::uint64_t written = 0;
  {
    McapWriter w(path);  // 1 MiB chunks
    const auto ch = w.addChannel(0, "/raw", "application/octet-stream");
    for (std::uint32_t i = 0; i < 30000; ++i)
      w.write(ch, i, i * 100'000ull, i * 100'000ull, samplePayload(i, 1000));
    w.close();
    written = w.bytes();
  }
  ASSERT_GT(written, 8 * kMiB);
  McapReader reader(path);
  hg::test::resetLargestAllocation();
  std::uint64_t bytes = 0;
  const McapSummary s = reader.scan([&](const McapMessageView& m) { bytes += m.data.size(); });
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.messages, 30000u);
  EXPECT_EQ(bytes, 30000u * 1000u);
  EXPECT_LT(hg::test::largestAllocation(), 3 * kMiB) << "one chunk, compressed and not, at a time";
}

}  // namespace
}  // namespace hg::session
