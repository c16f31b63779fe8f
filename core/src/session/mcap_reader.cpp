#include "hapticgrasp/session/mcap_reader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

namespace hg::session {

using namespace mcap;

namespace {

constexpr std::size_t kMaxWarnings = 100;
constexpr std::uint64_t kNoEnd = std::numeric_limits<std::uint64_t>::max();
// A chunk's fixed fields before its records: three times/sizes, the CRC, the
// compression string's length and the records' length.
constexpr std::size_t kChunkFixed = 8 * 3 + 4 + 4 + 8;

std::string mib(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1 << 20));
  return text;
}

std::string at(std::string_view what, std::uint64_t pos) {
  return std::string(what) + " at byte " + std::to_string(pos);
}

}  // namespace

// The state of one read: the window, the callback and what was found.
struct McapReader::Pass {
  const MessageCallback* onMessage = nullptr;
  std::uint64_t start = 0, end = kNoEnd;
  bool attachmentData = true;
  bool collect = false;  // keep attachments and metadata (scan) or pass them by (windows)
  bool lost = false;     // something was lost: lastGoodTime stops here
  bool stoppedEarly = false;
  std::uint64_t dataEnd = 0;  // where the DataEnd record was found (0: not found)
  std::uint64_t chunksRead = 0;
  McapSummary result;

  bool inWindow(std::uint64_t from, std::uint64_t to) const { return to >= start && from <= end; }
  // At most kMaxWarnings of them (a garbage file could make millions); `last` ones, that
  // say where and why the read ended, are always kept.
  void warn(std::string text, bool last = false) {
    auto& w = result.warnings;
    if (w.size() < kMaxWarnings || last)
      w.push_back(std::move(text));
    else if (w.size() == kMaxWarnings)
      w.push_back("further warnings left out");
  }
  // The "N messages recovered up to T s" that every loss reports.
  std::string recovered() const {
    char text[96];
    const double seconds =
        result.messages == 0
            ? 0.0
            : static_cast<double>(result.lastGoodTime_ns - result.firstTime_ns) * 1e-9;
    std::snprintf(text, sizeof text, "%llu messages recovered up to %.1f s",
                  static_cast<unsigned long long>(result.messages), seconds);
    return text;
  }
  void skipChunk(std::uint64_t pos, const std::string& why) {
    warn(at("chunk", pos) + ": " + why + "; skipped");
    ++result.chunksSkipped;
    lost = true;
  }
};

struct McapReader::ChunkHead {
  std::uint64_t start = 0, end = 0, uncompressed = 0;
  std::uint32_t crc = 0;
  std::string_view compression;
};

McapReader::McapReader(const std::string& path, Limits limits) : path_(path), limits_(limits) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw McapError("cannot open " + path + ": " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd_);
    throw McapError("cannot open " + path + ": not a regular file");
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
  std::string magic;
  if (size_ >= kMcapMagic.size()) readAt(0, kMcapMagic.size(), magic);
  if (magic != kMcapMagic) {
    ::close(fd_);
    throw McapError(path + " is not an MCAP file (no MCAP magic at its start)");
  }
  zstd_ = ZSTD_createDCtx();
  if (zstd_ == nullptr) {
    ::close(fd_);
    throw McapError("cannot read " + path + ": zstd could not allocate its context");
  }
  readIndex();
}

McapReader::~McapReader() {
  ::close(fd_);
  ZSTD_freeDCtx(zstd_);
}

void McapReader::readAt(std::uint64_t offset, std::uint64_t bytes, std::string& out) const {
  out.resize(bytes);
  std::uint64_t done = 0;
  while (done < bytes) {
    const ssize_t n =
        ::pread(fd_, out.data() + done, bytes - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw McapError("cannot read " + path_ + ": " + std::strerror(errno));
    if (n == 0) throw McapError("cannot read " + path_ + ": it shrank while being read");
    done += static_cast<std::uint64_t>(n);
  }
}

// ---- The summary: footer at the end, DataEnd and summary before it, all CRC-checked.

void McapReader::readIndex() {
  if (size_ < kMcapMagic.size() + kMcapTail) return;
  std::string tail;
  readAt(size_ - kMcapTail, kMcapTail, tail);
  const std::uint64_t footer = size_ - kMcapTail;
  if (tail.substr(kMcapFooterRecord) != kMcapMagic ||
      tail[0] != static_cast<char>(McapOp::Footer) || getLE(tail.data() + 1, 8) != 20)
    return;  // no footer: an unfinished file, which the scan reports
  footerFound_ = true;
  const std::uint64_t summaryStart = getLE(tail.data() + 9, 8);
  const std::uint32_t crc = static_cast<std::uint32_t>(getLE(tail.data() + 25, 4));
  auto warn = [&](const std::string& why) {
    indexWarnings_.push_back("summary: " + why + "; the file is read without its index");
  };
  if (summaryStart == 0) return warn("the footer points to none");
  if (summaryStart < kMcapMagic.size() + kMcapDataEndRecord || summaryStart > footer)
    return warn("the footer puts it at byte " + std::to_string(summaryStart) +
                ", outside the file");
  if (footer - summaryStart > limits_.maxSummaryBytes)
    return warn(mib(footer - summaryStart) + ", over the limit of " + mib(limits_.maxSummaryBytes));
  // DataEnd, the summary, and the footer's fields that the summary CRC covers.
  std::string bytes;
  readAt(summaryStart - kMcapDataEndRecord,
         footer + kMcapRecordPrefix + 16 - (summaryStart - kMcapDataEndRecord), bytes);
  if (bytes[0] != static_cast<char>(McapOp::DataEnd) || getLE(bytes.data() + 1, 8) != 4)
    return warn("no DataEnd record right before it at byte " + std::to_string(summaryStart));
  const std::string_view covered = std::string_view(bytes).substr(kMcapDataEndRecord);
  if (crc != 0 && mcapCrc32(covered) != crc) return warn("CRC mismatch");
  if (!parseSummary(covered.substr(0, footer - summaryStart), summaryStart)) return;
  dataEnd_ = summaryStart - kMcapDataEndRecord;
  indexed_ = true;
}

// The summary's records; all or nothing, so a damaged summary leaves no half-index.
bool McapReader::parseSummary(std::string_view summary, std::uint64_t summaryStart) {
  std::map<std::uint16_t, McapSchema> schemas;
  std::map<std::uint16_t, McapChannel> channels;
  std::vector<McapChunkInfo> chunks;
  std::uint64_t pos = 0;
  try {
    while (pos < summary.size()) {
      if (summary.size() - pos < kMcapRecordPrefix ||
          getLE(summary.data() + pos + 1, 8) > summary.size() - pos - kMcapRecordPrefix)
        throw McapError(at("a record runs past its end", summaryStart + pos));
      const auto op = static_cast<McapOp>(summary[pos]);
      const std::uint64_t length = getLE(summary.data() + pos + 1, 8);
      FieldReader f(summary.substr(pos + kMcapRecordPrefix, length), mcapOpName(summary[pos]));
      if (op == McapOp::Schema) {
        McapSchema s;
        s.id = f.u16();
        s.name = f.string();
        s.encoding = f.string();
        s.data = f.string();
        if (s.id != 0) schemas[s.id] = std::move(s);
      } else if (op == McapOp::Channel) {
        McapChannel c;
        c.id = f.u16();
        c.schemaId = f.u16();
        c.topic = f.string();
        c.messageEncoding = f.string();
        c.metadata = f.stringMap();
        channels[c.id] = std::move(c);
      } else if (op == McapOp::Statistics) {
        statisticsMessages_ = f.u64();
        haveStatistics_ = true;
      } else if (op == McapOp::ChunkIndex) {
        McapChunkInfo c;
        c.startTime_ns = f.u64();
        c.endTime_ns = f.u64();
        c.offset = f.u64();
        c.length = f.u64();
        f.string();  // message index offsets: a linear read of a chunk does not need them
        f.u64();
        c.compression = f.string();
        c.compressedBytes = f.u64();
        c.uncompressedBytes = f.u64();
        const std::uint64_t dataEnd = summaryStart - kMcapDataEndRecord;
        if (c.offset < kMcapMagic.size() || c.length < kMcapRecordPrefix || c.offset > dataEnd ||
            c.length > dataEnd - c.offset)
          throw McapError(at("a chunk index points outside the data section", summaryStart + pos));
        chunks.push_back(std::move(c));
      }
      pos += kMcapRecordPrefix + length;
    }
  } catch (const McapError& e) {
    indexWarnings_.push_back(std::string("summary: ") + e.what() +
                             "; the file is read without its index");
    haveStatistics_ = false;
    return false;
  }
  std::sort(chunks.begin(), chunks.end(),
            [](const auto& a, const auto& b) { return a.offset < b.offset; });
  schemas_ = std::move(schemas);
  channels_ = std::move(channels);
  chunkIndex_ = std::move(chunks);
  return true;
}

// ---- Reads.

McapSummary McapReader::scan(const MessageCallback& onMessage, bool attachmentData) {
  Pass pass;
  pass.onMessage = &onMessage;
  pass.attachmentData = attachmentData;
  pass.collect = true;
  pass.result.fileBytes = size_;
  pass.result.warnings = indexWarnings_;
  attachments_.clear();
  metadata_.clear();
  linearPass(pass);
  McapSummary& r = pass.result;
  r.complete = indexed_ && !pass.stoppedEarly && pass.dataEnd == dataEnd_;
  if (r.complete) r.bytesRecovered = size_;
  if (!r.complete && pass.dataEnd != 0 && !footerFound_)
    pass.warn("the file ends after its DataEnd record at byte " + std::to_string(pass.dataEnd) +
                  ", without its summary and footer: " + pass.recovered(),
              true);
  if (r.complete && haveStatistics_ && statisticsMessages_ != r.messages && r.chunksSkipped == 0)
    pass.warn("the summary counts " + std::to_string(statisticsMessages_) + " messages, " +
              std::to_string(r.messages) + " were read");
  return std::move(pass.result);
}

McapWindowRead McapReader::readMessages(std::uint64_t start_ns, std::uint64_t end_ns,
                                        const MessageCallback& onMessage) {
  Pass pass;
  pass.onMessage = &onMessage;
  pass.start = start_ns;
  pass.end = end_ns;
  McapWindowRead w;
  w.indexed = indexed_;
  if (indexed_) {
    for (const McapChunkInfo& chunk : chunkIndex_)
      if (pass.inWindow(chunk.startTime_ns, chunk.endTime_ns)) readIndexedChunk(pass, chunk);
    w.chunksInFile = chunkIndex_.size();
  } else {
    pass.result.warnings = indexWarnings_;
    linearPass(pass);
    w.chunksInFile = pass.result.chunks;
  }
  w.messages = pass.result.messages;
  w.chunksRead = pass.chunksRead;
  w.warnings = std::move(pass.result.warnings);
  return w;
}

// Records forward from the magic to DataEnd or to where the file stops making sense.
void McapReader::linearPass(Pass& pass) {
  std::uint64_t pos = kMcapMagic.size();
  std::string prefix;
  for (bool first = true;; first = false) {
    pass.result.bytesRecovered = pos;
    const std::uint64_t left = size_ - pos;
    if (left == 0) {
      pass.warn("the file ends at byte " + std::to_string(pos) +
                    " without its DataEnd record: " + pass.recovered(),
                true);
      break;
    }
    if (left < kMcapRecordPrefix) {
      pass.warn("the file ends inside a record header at byte " + std::to_string(pos) + ": " +
                    pass.recovered(),
                true);
      break;
    }
    readAt(pos, kMcapRecordPrefix, prefix);
    const auto op = static_cast<std::uint8_t>(prefix[0]);
    const std::uint64_t length = getLE(prefix.data() + 1, 8);
    if (first && op != static_cast<std::uint8_t>(McapOp::Header))
      pass.warn("no Header record after the magic");
    if (length > left - kMcapRecordPrefix) {
      const bool chunk = op == static_cast<std::uint8_t>(McapOp::Chunk);
      pass.warn("the file ends inside " +
                    at("a " + mcapOpName(op) + (chunk ? "" : " record"), pos) + " (it declares " +
                    std::to_string(length) + " bytes, " + std::to_string(left - kMcapRecordPrefix) +
                    " are left): " + pass.recovered(),
                true);
      pass.lost = pass.stoppedEarly = true;
      break;
    }
    if (op == static_cast<std::uint8_t>(McapOp::DataEnd)) {
      pass.dataEnd = pos;
      pass.result.bytesRecovered = pos + kMcapRecordPrefix + length;
      return;
    }
    if (!handleRecord(pass, pos, op, length)) {
      pass.lost = pass.stoppedEarly = true;
      break;
    }
    pos += kMcapRecordPrefix + length;
  }
  // A finished file damaged in its middle still has an index to the chunks after the damage.
  if (indexed_ && pass.stoppedEarly) {
    std::uint64_t resumed = 0;
    for (const McapChunkInfo& chunk : chunkIndex_)
      if (chunk.offset >= pos && pass.inWindow(chunk.startTime_ns, chunk.endTime_ns)) {
        readIndexedChunk(pass, chunk);
        ++resumed;
      }
    pass.warn(std::to_string(resumed) + " chunks after byte " + std::to_string(pos) +
                  " read through the summary's chunk index",
              true);
  } else {
    pass.lost = true;
  }
}

// One record of the data section; false when the file stops making sense here.
bool McapReader::handleRecord(Pass& pass, std::uint64_t pos, std::uint8_t op,
                              std::uint64_t length) {
  const std::string what = mcapOpName(op);
  switch (static_cast<McapOp>(op)) {
    case McapOp::Chunk:
      return handleChunk(pass, pos, length);
    case McapOp::Attachment:
      if (pass.collect) readAttachment(pass, pos, length);
      return true;
    case McapOp::MessageIndex:  // a linear read does not need the indexes
    case McapOp::ChunkIndex:
    case McapOp::AttachmentIndex:
    case McapOp::MetadataIndex:
    case McapOp::Statistics:
    case McapOp::SummaryOffset:
      return true;
    case McapOp::Footer:
      pass.warn(at("a footer before any DataEnd record", pos));
      return false;
    case McapOp::Header:
    case McapOp::Schema:
    case McapOp::Channel:
    case McapOp::Message:
    case McapOp::Metadata:
      break;
    default:
      if (op == 0) {
        pass.warn(at("opcode 0x00, which no record has,", pos) + ": the data is damaged from here");
        return false;
      }
      if (op < 0x80) pass.warn(at("an unknown " + what + " record", pos) + ", skipped");
      return true;  // 0x80-0xFF: application records, skipped as the specification says
  }
  if (length > limits_.maxRecordBytes) {
    pass.warn(at("a " + what + " record", pos) + " of " + mib(length) + ", over the limit of " +
              mib(limits_.maxRecordBytes) + "; skipped");
    return true;
  }
  readAt(pos + kMcapRecordPrefix, length, record_);
  try {
    FieldReader f(record_, what);
    if (op == static_cast<std::uint8_t>(McapOp::Header)) {
      profile_ = f.string();
      library_ = f.string();
    } else if (op == static_cast<std::uint8_t>(McapOp::Schema)) {
      addSchema(pass, pos, record_);
    } else if (op == static_cast<std::uint8_t>(McapOp::Channel)) {
      addChannel(pass, pos, record_);
    } else if (op == static_cast<std::uint8_t>(McapOp::Metadata)) {
      McapMetadata m;
      m.name = f.string();
      m.entries = f.stringMap();
      if (pass.collect) metadata_.push_back(std::move(m));
    } else {
      McapMessageView m;
      m.channel = f.u16();
      m.sequence = f.u32();
      m.logTime_ns = f.u64();
      m.publishTime_ns = f.u64();
      m.data = f.rest();
      if (channels_.count(m.channel) == 0)
        pass.warn(at("a message on undefined channel " + std::to_string(m.channel), pos) +
                  ", skipped");
      else
        deliver(pass, m);
    }
  } catch (const McapError& e) {
    pass.warn(at(what, pos) + ": " + e.what() + "; skipped");
  }
  return true;
}

bool McapReader::handleChunk(Pass& pass, std::uint64_t pos, std::uint64_t length) {
  ++pass.result.chunks;
  if (indexed_ && !chunkIndex_.empty()) {
    // Where the index knows every chunk, one it does not know means a damaged length.
    const auto it =
        std::lower_bound(chunkIndex_.begin(), chunkIndex_.end(), pos,
                         [](const McapChunkInfo& c, std::uint64_t p) { return c.offset < p; });
    if (it == chunkIndex_.end() || it->offset != pos || it->length != kMcapRecordPrefix + length) {
      --pass.result.chunks;
      pass.warn(at("a chunk", pos) +
                " that the summary's index does not list: the data is damaged from here");
      return false;
    }
  }
  if (length > limits_.maxRecordBytes) {
    pass.skipChunk(pos,
                   mib(length) + " compressed, over the limit of " + mib(limits_.maxRecordBytes));
    return true;
  }
  if (length >= 16 && (pass.start > 0 || pass.end < kNoEnd)) {
    readAt(pos + kMcapRecordPrefix, 16, record_);
    if (!pass.inWindow(getLE(record_.data(), 8), getLE(record_.data() + 8, 8))) return true;
  }
  readAt(pos + kMcapRecordPrefix, length, record_);
  readChunk(pass, pos, record_);
  return true;
}

void McapReader::readIndexedChunk(Pass& pass, const McapChunkInfo& chunk) {
  if (chunk.length - kMcapRecordPrefix > limits_.maxRecordBytes) {
    pass.skipChunk(chunk.offset,
                   mib(chunk.length) + ", over the limit of " + mib(limits_.maxRecordBytes));
    return;
  }
  readAt(chunk.offset, chunk.length, record_);
  if (record_[0] != static_cast<char>(McapOp::Chunk) ||
      getLE(record_.data() + 1, 8) != chunk.length - kMcapRecordPrefix) {
    pass.skipChunk(chunk.offset, "not the chunk record that the summary's index describes");
    return;
  }
  readChunk(pass, chunk.offset, std::string_view(record_).substr(kMcapRecordPrefix));
}

// A chunk's content: fixed fields, decompress, check, then its records.
void McapReader::readChunk(Pass& pass, std::uint64_t pos, std::string_view content) {
  ChunkHead head;
  std::string_view compressed;
  try {
    FieldReader f(content, "chunk");
    head.start = f.u64();
    head.end = f.u64();
    head.uncompressed = f.u64();
    head.crc = f.u32();
    head.compression = f.string();
    compressed = f.bytes(f.u64());
  } catch (const McapError& e) {
    pass.skipChunk(pos, e.what());
    return;
  }
  std::string_view records;
  if (!decompress(pass, pos, head, compressed, records)) return;
  if (head.crc != 0 && mcapCrc32(records) != head.crc) {
    pass.skipChunk(pos, "CRC mismatch");
    return;
  }
  ++pass.chunksRead;
  readChunkRecords(pass, pos, records);
}

// Every limit is checked against what the chunk declares before any memory is taken.
bool McapReader::decompress(Pass& pass, std::uint64_t pos, const ChunkHead& head,
                            std::string_view compressed, std::string_view& records) {
  const std::uint64_t n = head.uncompressed;
  if (head.compression.empty()) {
    if (n != compressed.size()) {
      pass.skipChunk(pos, "it declares " + std::to_string(n) + " bytes and holds " +
                              std::to_string(compressed.size()));
      return false;
    }
    records = compressed;
    return true;
  }
  if (head.compression != "zstd") {
    pass.skipChunk(pos, "compression '" + std::string(head.compression) + "' is not supported");
    return false;
  }
  if (n > limits_.maxChunkUncompressed) {
    pass.skipChunk(pos, "it declares " + mib(n) + " uncompressed, over the limit of " +
                            mib(limits_.maxChunkUncompressed));
    return false;
  }
  const double ratio =
      static_cast<double>(n) / static_cast<double>(std::max<std::size_t>(compressed.size(), 1));
  if (n > limits_.ratioCheckAbove && ratio > limits_.maxCompressionRatio) {
    pass.skipChunk(pos, "it declares " + mib(n) + " from " + std::to_string(compressed.size()) +
                            " bytes, a compression ratio over the limit of " +
                            std::to_string(static_cast<long>(limits_.maxCompressionRatio)) + ":1");
    return false;
  }
  const unsigned long long frame = ZSTD_getFrameContentSize(compressed.data(), compressed.size());
  if (frame == ZSTD_CONTENTSIZE_ERROR || (frame != ZSTD_CONTENTSIZE_UNKNOWN && frame > n)) {
    pass.skipChunk(pos, frame == ZSTD_CONTENTSIZE_ERROR
                            ? std::string("its records are not zstd")
                            : "its zstd frame holds " + std::to_string(frame) +
                                  " bytes, more than the " + std::to_string(n) + " it declares");
    return false;
  }
  if (n > chunkCapacity_) {
    chunkBuffer_.reset();
    chunkBuffer_.reset(new char[n]);
    chunkCapacity_ = n;
  }
  // The output capacity is the declared size: zstd stops there whatever the frame says.
  const std::size_t got =
      ZSTD_decompressDCtx(zstd_, chunkBuffer_.get(), n, compressed.data(), compressed.size());
  if (ZSTD_isError(got) || got != n) {
    pass.skipChunk(pos, ZSTD_isError(got)
                            ? std::string("zstd: ") + ZSTD_getErrorName(got)
                            : "it decompresses to " + std::to_string(got) + " bytes, not the " +
                                  std::to_string(n) + " it declares");
    return false;
  }
  records = std::string_view(chunkBuffer_.get(), n);
  return true;
}

void McapReader::readChunkRecords(Pass& pass, std::uint64_t pos, std::string_view records) {
  std::uint64_t undefined = 0;
  for (std::size_t i = 0; i < records.size();) {
    const std::size_t left = records.size() - i;
    if (left < kMcapRecordPrefix || getLE(records.data() + i + 1, 8) > left - kMcapRecordPrefix) {
      pass.warn(at("chunk", pos) + ": a record at offset " + std::to_string(i) +
                " runs past the chunk's end; the rest of the chunk is ignored");
      pass.lost = true;
      break;
    }
    const auto op = static_cast<McapOp>(records[i]);
    const std::uint64_t length = getLE(records.data() + i + 1, 8);
    const std::string_view content = records.substr(i + kMcapRecordPrefix, length);
    i += kMcapRecordPrefix + length;
    if (op == McapOp::Schema) {
      addSchema(pass, pos, content);
    } else if (op == McapOp::Channel) {
      addChannel(pass, pos, content);
    } else if (op == McapOp::Message) {
      if (content.size() < 2 + 4 + 8 + 8) {
        pass.warn(at("chunk", pos) + ": a message record shorter than its fields, skipped");
        continue;
      }
      McapMessageView m;
      m.channel = static_cast<std::uint16_t>(getLE(content.data(), 2));
      m.sequence = static_cast<std::uint32_t>(getLE(content.data() + 2, 4));
      m.logTime_ns = getLE(content.data() + 6, 8);
      m.publishTime_ns = getLE(content.data() + 14, 8);
      m.data = content.substr(22);
      if (channels_.count(m.channel) == 0)
        ++undefined;
      else
        deliver(pass, m);
    } else {
      pass.warn(at("chunk", pos) + ": a " + mcapOpName(static_cast<std::uint8_t>(op)) +
                " record inside it, ignored");
    }
  }
  if (undefined > 0)
    pass.warn(at("chunk", pos) + ": " + std::to_string(undefined) +
              " messages on channels that no Channel record defines, skipped");
}

void McapReader::addSchema(Pass& pass, std::uint64_t pos, std::string_view content) {
  try {
    FieldReader f(content, "schema");
    McapSchema s;
    s.id = f.u16();
    s.name = f.string();
    s.encoding = f.string();
    s.data = f.string();
    if (s.id == 0) return;  // invalid by the specification: ignored
    const auto [it, added] = schemas_.try_emplace(s.id, s);
    if (!added && !(it->second == s))
      pass.warn(at("schema " + std::to_string(s.id), pos) +
                " differs from its first definition, which is kept");
  } catch (const McapError& e) {
    pass.warn(at("near byte", pos) + ": " + e.what());
  }
}

void McapReader::addChannel(Pass& pass, std::uint64_t pos, std::string_view content) {
  try {
    FieldReader f(content, "channel");
    McapChannel c;
    c.id = f.u16();
    c.schemaId = f.u16();
    c.topic = f.string();
    c.messageEncoding = f.string();
    c.metadata = f.stringMap();
    const auto [it, added] = channels_.try_emplace(c.id, c);
    if (!added && !(it->second == c))
      pass.warn(at("channel " + std::to_string(c.id), pos) +
                " differs from its first definition, which is kept");
  } catch (const McapError& e) {
    pass.warn(at("near byte", pos) + ": " + e.what());
  }
}

// Attachment fields are read first, the data only when wanted and within the limit.
void McapReader::readAttachment(Pass& pass, std::uint64_t pos, std::uint64_t length) {
  McapAttachment a;
  a.offset = pos;
  std::size_t head = 0;
  try {
    readAt(pos + kMcapRecordPrefix, std::min<std::uint64_t>(length, 1 << 20), record_);
    FieldReader f(record_, "attachment");
    a.logTime_ns = f.u64();
    a.createTime_ns = f.u64();
    a.name = f.string();
    a.mediaType = f.string();
    a.dataBytes = f.u64();
    head = f.offset();
    if (length < head + 4 || a.dataBytes != length - head - 4)
      throw McapError("its data length disagrees with its record length");
  } catch (const McapError& e) {
    pass.warn(at("attachment", pos) + ": " + e.what() + "; skipped");
    return;
  }
  if (pass.attachmentData && a.dataBytes > limits_.maxAttachmentBytes) {
    pass.warn(at("attachment '" + a.name + "'", pos) + ": " + mib(a.dataBytes) +
              ", over the limit of " + mib(limits_.maxAttachmentBytes) +
              "; its data is not loaded");
  } else if (pass.attachmentData) {
    readAt(pos + kMcapRecordPrefix, length, record_);
    const auto crc = static_cast<std::uint32_t>(getLE(record_.data() + length - 4, 4));
    if (crc != 0 && mcapCrc32(std::string_view(record_).substr(0, length - 4)) != crc) {
      pass.warn(at("attachment '" + a.name + "'", pos) + ": CRC mismatch; its data is not loaded");
    } else {
      a.data = record_.substr(head, a.dataBytes);
      a.dataLoaded = true;
    }
  }
  attachments_.push_back(std::move(a));
}

void McapReader::deliver(Pass& pass, const McapMessageView& m) const {
  if (m.logTime_ns < pass.start || m.logTime_ns > pass.end) return;
  McapSummary& r = pass.result;
  r.firstTime_ns = r.messages == 0 ? m.logTime_ns : std::min(r.firstTime_ns, m.logTime_ns);
  r.lastTime_ns = r.messages == 0 ? m.logTime_ns : std::max(r.lastTime_ns, m.logTime_ns);
  if (!pass.lost)
    r.lastGoodTime_ns = r.messages == 0 ? m.logTime_ns : std::max(r.lastGoodTime_ns, m.logTime_ns);
  ++r.messages;
  ++r.perChannel[m.channel];
  if (pass.onMessage != nullptr && *pass.onMessage) (*pass.onMessage)(m);
}

}  // namespace hg::session
