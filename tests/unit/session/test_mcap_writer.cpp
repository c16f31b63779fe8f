// The MCAP writer: what it writes reads back exactly (through McapReader and through the
// raw records), chunks close on size and on time, the layout is the one the reference
// reader (@mcap/core) insists on, and write errors stop it with a clear message.
#include "hapticgrasp/session/mcap_writer.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <zstd.h>

#include <cstring>
#include <map>

#include "alloc_counter.hpp"
#include "hapticgrasp/session/mcap_reader.hpp"
#include "session/mcap_fixtures.hpp"

namespace hg::session {
namespace {

using namespace test;
using mcap::FieldReader;
using mcap::getLE;

struct Collected {
  std::vector<SampleMessage> messages;
  McapSummary summary;
};

Collected readAll(McapReader& reader) {
  Collected c;
  c.summary = reader.scan([&](const McapMessageView& m) {
    c.messages.push_back({m.channel, m.sequence, m.logTime_ns, std::string(m.data)});
  });
  return c;
}

TEST(McapWriter, EmptyFileIsAFinishedMcap) {
  TempDir dir;
  const std::string path = dir.file("empty.mcap");
  McapWriter w(path);
  w.close();
  w.close();  // idempotent
  const std::string bytes = readFile(path);
  EXPECT_EQ(w.bytes(), bytes.size());
  EXPECT_EQ(bytes.substr(0, 8), kMcapMagic);
  EXPECT_EQ(bytes.substr(bytes.size() - 8), kMcapMagic);
  McapReader reader(path);
  EXPECT_TRUE(reader.indexed());
  const McapSummary s = reader.scan();
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.messages, 0u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  EXPECT_EQ(reader.library(), "hapticgrasp");
}

TEST(McapWriter, RoundTripsSchemasChannelsMessagesAttachmentsAndMetadata) {
  TempDir dir;
  const std::string path = dir.file("round.mcap");
  McapWriter::Options options;
  options.chunkBytes = 16 << 10;  // several size-closed chunks ...
  options.chunkSeconds = 0.25;    // ... and time-closed ones at 1 kHz
  options.profile = "hg-test";
  const Sample sample = writeSample(path, 3000, options);
  ASSERT_GE(sample.chunks, 12u);

  McapReader reader(path);
  const Collected got = readAll(reader);
  EXPECT_TRUE(got.summary.complete);
  EXPECT_TRUE(got.summary.warnings.empty()) << got.summary.warnings.front();
  EXPECT_EQ(got.summary.chunks, sample.chunks);
  EXPECT_EQ(got.summary.bytesRecovered, sample.bytes);
  EXPECT_EQ(reader.profile(), "hg-test");
  ASSERT_EQ(got.messages.size(), sample.messages.size());
  for (std::size_t i = 0; i < got.messages.size(); ++i) {  // order, channel, time, payload
    const SampleMessage& a = got.messages[i];
    const SampleMessage& b = sample.messages[i];
    ASSERT_EQ(a.sequence, b.sequence) << i;
    ASSERT_EQ(a.channel, b.channel) << i;
    ASSERT_EQ(a.logTime_ns, b.logTime_ns) << i;
    ASSERT_EQ(a.data, b.data) << i;
  }
  EXPECT_EQ(got.summary.perChannel.at(1), 1500u);  // i % 4 == 0 or 2
  EXPECT_EQ(got.summary.perChannel.at(2), 750u);   // i % 4 == 1
  EXPECT_EQ(got.summary.perChannel.at(3), 750u);   // i % 4 == 3
  EXPECT_EQ(got.summary.firstTime_ns, sample.messages.front().logTime_ns);
  EXPECT_EQ(got.summary.lastTime_ns, sample.messages.back().logTime_ns);

  ASSERT_EQ(reader.schemas().size(), 2u);
  EXPECT_EQ(reader.schemas().at(2).name, "foxglove.Log");
  EXPECT_EQ(reader.schemas().at(2).encoding, "jsonschema");
  EXPECT_EQ(reader.schemas().at(2).data, R"({"type":"object","title":"Log"})");
  ASSERT_EQ(reader.channels().size(), 3u);
  EXPECT_EQ(reader.channels().at(1).topic, "/tick");
  EXPECT_EQ(reader.channels().at(1).metadata.at("rate_hz"), "1000");
  EXPECT_EQ(reader.channels().at(3).schemaId, 2);
  EXPECT_EQ(reader.channels().at(3).metadata.size(), 2u);
  EXPECT_EQ(reader.channels().at(2).messageEncoding, "json");

  ASSERT_EQ(reader.attachments().size(), 1u);
  const McapAttachment& a = reader.attachments()[0];
  EXPECT_EQ(a.name, "part.brep");
  EXPECT_EQ(a.mediaType, "application/octet-stream");
  EXPECT_EQ(a.logTime_ns, sample.messages[1000].logTime_ns);
  EXPECT_EQ(a.createTime_ns, a.logTime_ns - 5);
  EXPECT_TRUE(a.dataLoaded);
  EXPECT_EQ(a.data, samplePayload(999, 5000));
  ASSERT_EQ(reader.metadata().size(), 1u);
  EXPECT_EQ(reader.metadata()[0].name, "session");
  EXPECT_EQ(reader.metadata()[0].entries.at("device"), "scripted");
}

TEST(McapWriter, ClosesChunksOnTime) {
  TempDir dir;
  const std::string path = dir.file("time.mcap");
  McapWriter::Options options;
  options.chunkBytes = 64 << 20;
  options.chunkSeconds = 0.5;
  const Sample sample = writeSample(path, 3200, options, 0, false);  // 0 .. 3.199 s, messages only
  EXPECT_EQ(sample.chunks, 7u);  // [0, 0.5), [0.5, 1), ..., [3, 3.2)
  McapReader reader(path);
  ASSERT_EQ(reader.chunkIndex().size(), 7u);
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_EQ(reader.chunkIndex()[i].startTime_ns, i * 500'000'000ull);
    EXPECT_EQ(reader.chunkIndex()[i].endTime_ns,
              std::min<std::uint64_t>(i * 500 + 499, 3199) * 1'000'000ull);
  }
}

TEST(McapWriter, ClosesChunksOnSize) {
  TempDir dir;
  const std::string path = dir.file("size.mcap");
  McapWriter::Options options;
  options.chunkBytes = 8 << 10;
  options.chunkSeconds = 0;  // no time limit
  const Sample sample = writeSample(path, 2000, options);
  McapReader reader(path);
  const auto& chunks = reader.chunkIndex();
  ASSERT_EQ(chunks.size(), sample.chunks);
  ASSERT_GE(chunks.size(), 20u);
  // Every chunk but the ones an attachment or metadata record closed reaches the size;
  // none goes past it by more than one message and the schema and channel records.
  std::size_t full = 0;
  for (const McapChunkInfo& c : chunks) {
    EXPECT_LT(c.uncompressedBytes, (8u << 10) + 300 + 200) << c.offset;
    full += c.uncompressedBytes >= (8u << 10);
    EXPECT_LT(c.compressedBytes, c.uncompressedBytes) << "zstd did nothing";
  }
  EXPECT_GE(full, chunks.size() - 3);
}

// The open chunk reaches the OS at flush(): a reader sees it while the file is still open.
TEST(McapWriter, FlushHandsTheOpenChunkToTheOs) {
  TempDir dir;
  const std::string path = dir.file("flush.mcap");
  McapWriter w(path);
  const auto ch = w.addChannel(0, "/raw", "application/octet-stream");
  for (std::uint32_t i = 0; i < 100; ++i) w.write(ch, i, 1000 + i, 1000 + i, samplePayload(i, 64));
  EXPECT_EQ(McapReader(path).scan().messages, 0u) << "nothing written before flush";
  w.flush();
  EXPECT_EQ(w.chunks(), 1u);
  McapReader reader(path);
  const McapSummary s = reader.scan();
  EXPECT_FALSE(s.complete);
  EXPECT_EQ(s.messages, 100u);
  EXPECT_EQ(s.lastGoodTime_ns, 1099u);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings.back().find("without its DataEnd record: 100 messages recovered"),
            std::string::npos)
      << s.warnings.back();
  w.flush();  // nothing open: no empty chunk
  EXPECT_EQ(w.chunks(), 1u);
}

// The layout @mcap/core's indexed reader checks: DataEnd 13 bytes before the summary; each
// chunk followed by its message indexes, contiguous, as long as the chunk index says, with
// the messages' own log times and offsets; summary offsets per group; CRCs.
TEST(McapWriter, IndexesAreTheOnesTheReferenceReaderChecks) {
  TempDir dir;
  const std::string path = dir.file("layout.mcap");
  McapWriter::Options options;
  options.chunkBytes = 16 << 10;
  const Sample sample = writeSample(path, 1500, options);
  const std::string file = readFile(path);
  const std::string_view f(file);
  const std::uint64_t footer = file.size() - kMcapTail;
  ASSERT_EQ(file[footer], static_cast<char>(McapOp::Footer));
  const std::uint64_t summaryStart = getLE(file.data() + footer + 9, 8);
  const std::uint64_t offsetsStart = getLE(file.data() + footer + 17, 8);
  ASSERT_GT(summaryStart, 0u);
  EXPECT_EQ(file[summaryStart - 13], static_cast<char>(McapOp::DataEnd));
  EXPECT_EQ(getLE(file.data() + footer + 25, 4),
            mcapCrc32(f.substr(summaryStart, footer + 25 - summaryStart)));
  const std::uint32_t dataCrc =
      static_cast<std::uint32_t>(getLE(file.data() + summaryStart - 4, 4));
  EXPECT_EQ(dataCrc, mcapCrc32(f.substr(0, summaryStart - 13)));

  std::map<std::uint8_t, std::pair<std::uint64_t, std::uint64_t>> groups;   // from the records
  std::map<std::uint8_t, std::pair<std::uint64_t, std::uint64_t>> offsets;  // as declared
  std::uint64_t chunks = 0, indexed = 0;
  for (std::uint64_t pos = summaryStart; pos < footer;) {
    const auto op = static_cast<std::uint8_t>(file[pos]);
    const std::uint64_t length = getLE(file.data() + pos + 1, 8);
    FieldReader r(f.substr(pos + 9, length), "summary");
    if (pos < offsetsStart) {
      auto& g = groups[op];
      if (g.second == 0) g.first = pos;
      g.second += 9 + length;
    } else {
      ASSERT_EQ(op, static_cast<std::uint8_t>(McapOp::SummaryOffset));
      const std::uint8_t groupOp = r.u8();
      const std::uint64_t start = r.u64();
      offsets[groupOp] = {start, r.u64()};
    }
    if (op == static_cast<std::uint8_t>(McapOp::ChunkIndex)) {
      ++chunks;
      const std::uint64_t start = r.u64(), end = r.u64(), offset = r.u64(), chunkLength = r.u64();
      FieldReader map(r.string(), "offsets");
      const std::uint64_t indexLength = r.u64();
      EXPECT_EQ(r.string(), "zstd");
      const std::uint64_t compressed = r.u64(), uncompressed = r.u64();
      // The chunk itself, decompressed.
      ASSERT_EQ(file[offset], static_cast<char>(McapOp::Chunk));
      FieldReader chunk(f.substr(offset + 9, chunkLength - 9), "chunk");
      EXPECT_EQ(chunk.u64(), start);
      EXPECT_EQ(chunk.u64(), end);
      EXPECT_EQ(chunk.u64(), uncompressed);
      const std::uint32_t crc = chunk.u32();
      EXPECT_EQ(chunk.string(), "zstd");
      const std::string_view src = chunk.bytes(chunk.u64());
      ASSERT_EQ(src.size(), compressed);
      std::string records(uncompressed, '\0');
      ASSERT_EQ(ZSTD_decompress(records.data(), records.size(), src.data(), src.size()),
                uncompressed);
      EXPECT_EQ(mcapCrc32(records), crc);
      // Its message indexes: right after it, contiguous, exactly indexLength long.
      std::uint64_t expected = offset + chunkLength;
      while (map.left() > 0) {
        const std::uint16_t channel = map.u16();
        const std::uint64_t at = map.u64();
        ASSERT_EQ(at, expected) << "message indexes not contiguous";
        ASSERT_EQ(file[at], static_cast<char>(McapOp::MessageIndex));
        const std::uint64_t miLength = getLE(file.data() + at + 1, 8);
        FieldReader mi(f.substr(at + 9, miLength), "message index");
        EXPECT_EQ(mi.u16(), channel);
        FieldReader entries(mi.bytes(mi.u32()), "entries");
        while (entries.left() > 0) {
          const std::uint64_t time = entries.u64(), inChunk = entries.u64();
          ASSERT_EQ(records[inChunk], static_cast<char>(McapOp::Message));
          EXPECT_EQ(getLE(records.data() + inChunk + 9, 2), channel);
          EXPECT_EQ(getLE(records.data() + inChunk + 9 + 6, 8), time);
          ++indexed;
        }
        expected = at + 9 + miLength;
      }
      EXPECT_EQ(expected - (offset + chunkLength), indexLength);
    }
    pos += 9 + length;
  }
  EXPECT_EQ(chunks, sample.chunks);
  EXPECT_EQ(indexed, sample.messages.size());
  EXPECT_EQ(groups, offsets);
  for (const McapOp op : {McapOp::Schema, McapOp::Channel, McapOp::Statistics, McapOp::ChunkIndex,
                          McapOp::AttachmentIndex, McapOp::MetadataIndex})
    EXPECT_EQ(groups.count(static_cast<std::uint8_t>(op)), 1u)
        << mcapOpName(static_cast<std::uint8_t>(op));
}

TEST(McapWriter, FullDiskThrowsNamingTheFileAndTheError) {
  try {
    McapWriter w("/dev/full");
    FAIL() << "wrote to /dev/full";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::strerror(ENOSPC)), std::string::npos) << e.what();
  }
  try {
    McapWriter w("/nonexistent-dir/x.mcap");
    FAIL() << "created a file in a missing directory";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write /nonexistent-dir/x.mcap: No such file"),
              std::string::npos)
        << e.what();
  }
}

// A write error in the middle of a recording (here the file size limit: EFBIG) stops the
// writer: every later call throws, the destructor does not, and the file reads up to the
// last chunk that made it.
TEST(McapWriter, WriteErrorStopsTheWriter) {
  TempDir dir;
  const std::string path = dir.file("limited.mcap");
  rlimit saved{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto oldHandler = signal(SIGXFSZ, SIG_IGN);
  rlimit limited = saved;
  limited.rlim_cur = 64 << 10;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  std::string error;
  std::uint64_t written = 0;
  {
    McapWriter::Options options;
    options.chunkBytes = 4 << 10;
    options.zstdLevel = -5;  // fast and barely compressing: the limit comes soon
    McapWriter w(path, options);
    const auto ch = w.addChannel(0, "/raw", "application/octet-stream");
    try {
      for (std::uint32_t i = 0; i < 100000; ++i, ++written)
        w.write(ch, i, i, i, samplePayload(i, 200));
    } catch (const McapError& e) {
      error = e.what();
    }
    EXPECT_THROW(w.write(ch, 0, 0, 0, "x"), McapError);
    EXPECT_THROW(w.flush(), McapError);
    EXPECT_THROW(w.attach("a", "b", 0, 0, "c"), McapError);
    EXPECT_THROW(w.close(), McapError);
    w.close();  // closed now: idempotent, quiet
  }             // the destructor does not throw
  setrlimit(RLIMIT_FSIZE, &saved);
  signal(SIGXFSZ, oldHandler);
  EXPECT_NE(error.find("cannot write " + path + ": " + std::strerror(EFBIG)), std::string::npos)
      << error;
  ASSERT_LT(written, 100000u);

  McapReader reader(path);
  const McapSummary s = reader.scan();
  EXPECT_FALSE(s.complete);
  EXPECT_GT(s.messages, 0u);
  EXPECT_LE(s.messages, written);
  EXPECT_LE(s.bytesRecovered, 64u << 10);
}

TEST(McapWriter, RefusesUnknownIdsAndWritesAfterClose) {
  TempDir dir;
  McapWriter w(dir.file("ids.mcap"));
  EXPECT_THROW(w.addChannel(1, "/a", "json"), McapError);  // no schema 1 yet
  const auto s = w.addSchema("S", "jsonschema", "{}");
  const auto c = w.addChannel(s, "/a", "json");
  EXPECT_EQ(s, 1);
  EXPECT_EQ(c, 1);
  EXPECT_THROW(w.write(2, 0, 0, 0, "x"), McapError);
  EXPECT_THROW(w.write(0, 0, 0, 0, "x"), McapError);
  w.write(c, 0, 0, 0, "x");
  w.close();
  EXPECT_THROW(w.write(c, 1, 1, 1, "y"), McapError);
  EXPECT_EQ(w.messages(), 1u);
}

// Once its buffers have grown, the writer allocates per chunk at most (the summary's chunk
// index grows), never per message.
TEST(McapWriter, AllocatesNothingPerMessageOnceWarm) {
  TempDir dir;
  McapWriter::Options options;
  options.chunkBytes = 64 << 10;
  options.chunkSeconds = 0;
  McapWriter w(dir.file("alloc.mcap"), options);
  const auto ch = w.addChannel(0, "/raw", "application/octet-stream");
  const std::string payload = samplePayload(1, 240);
  std::uint32_t i = 0;
  while (w.chunks() < 3) w.write(ch, i, i, i, payload), ++i;
  const std::uint64_t chunks = w.chunks();
  const long before = hg::test::allocations();
  for (std::uint32_t k = 0; k < 5000; ++k) w.write(ch, i, i, i, payload), ++i;
  const long allocations = hg::test::allocations() - before;
  const std::uint64_t closed = w.chunks() - chunks;
  EXPECT_GE(closed, 15u);
  EXPECT_LE(allocations, static_cast<long>(closed)) << "per 5000 messages";
}

}  // namespace
}  // namespace hg::session
