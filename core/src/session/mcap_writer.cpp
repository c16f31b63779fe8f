#include "hapticgrasp/session/mcap_writer.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

namespace hg::session {

using namespace mcap;

namespace {

std::string errnoText(int err) { return std::strerror(err); }

}  // namespace

McapWriter::McapWriter(const std::string& path, Options options)
    : path_(path), options_(std::move(options)) {
  if (options_.chunkSeconds > 0)
    chunkNs_ = static_cast<std::uint64_t>(std::llround(options_.chunkSeconds * 1e9));
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) throw McapError("cannot write " + path + ": " + errnoText(errno));
  zstd_ = ZSTD_createCCtx();
  if (zstd_ == nullptr) {
    closeFile();
    throw McapError("cannot write " + path + ": zstd could not allocate its context");
  }
  ZSTD_CCtx_setParameter(zstd_, ZSTD_c_compressionLevel, options_.zstdLevel);
  out_.assign(kMcapMagic);
  const std::size_t header = beginRecord(out_, McapOp::Header);
  putString(out_, options_.profile);
  putString(out_, options_.library);
  endRecord(out_, header);
  try {
    writeOut(out_);
  } catch (...) {
    closeFile();
    ZSTD_freeCCtx(zstd_);
    throw;
  }
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (...) {  // the destructor must not throw; close() reports to those who call it
  }
  closeFile();
  ZSTD_freeCCtx(zstd_);
}

std::uint16_t McapWriter::addSchema(std::string_view name, std::string_view encoding,
                                    std::string_view data) {
  checkWritable();
  if (schemas_.size() >= 0xFFFF) throw McapError(path_ + ": more than 65535 schemas");
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  Schema& schema = schemas_.emplace_back();
  const std::size_t start = beginRecord(schema.record, McapOp::Schema);
  putU16(schema.record, id);
  putString(schema.record, name);
  putString(schema.record, encoding);
  putString(schema.record, data);
  endRecord(schema.record, start);
  return id;
}

std::uint16_t McapWriter::addChannel(std::uint16_t schemaId, std::string_view topic,
                                     std::string_view messageEncoding,
                                     const std::map<std::string, std::string>& metadata) {
  checkWritable();
  if (schemaId > schemas_.size())
    throw McapError(path_ + ": channel '" + std::string(topic) + "' names schema " +
                    std::to_string(schemaId) + ", which was never added");
  if (channels_.size() >= 0xFFFF) throw McapError(path_ + ": more than 65535 channels");
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  Channel& channel = channels_.emplace_back();
  channel.schemaId = schemaId;
  const std::size_t start = beginRecord(channel.record, McapOp::Channel);
  putU16(channel.record, id);
  putU16(channel.record, schemaId);
  putString(channel.record, topic);
  putString(channel.record, messageEncoding);
  putStringMap(channel.record, metadata);
  endRecord(channel.record, start);
  return id;
}

void McapWriter::write(std::uint16_t channelId, std::uint32_t sequence, std::uint64_t logTime_ns,
                       std::uint64_t publishTime_ns, std::string_view data) {
  checkWritable();
  if (channelId == 0 || channelId > channels_.size())
    throw McapError(path_ + ": message on channel " + std::to_string(channelId) +
                    ", which was never added");
  // Time closes the chunk before this message, so a chunk spans at most chunkSeconds.
  if (chunkMessages_ > 0 && chunkNs_ > 0 && logTime_ns >= chunkStart_ &&
      logTime_ns - chunkStart_ >= chunkNs_)
    closeChunk();
  Channel& channel = channels_[channelId - 1];
  if (channel.chunkSerial != chunkSerial_) declareInChunk(channelId, channel);
  channel.index.emplace_back(logTime_ns, chunk_.size());
  putU8(chunk_, static_cast<std::uint8_t>(McapOp::Message));
  putU64(chunk_, 2 + 4 + 8 + 8 + data.size());
  putU16(chunk_, channelId);
  putU32(chunk_, sequence);
  putU64(chunk_, logTime_ns);
  putU64(chunk_, publishTime_ns);
  chunk_.append(data);

  chunkStart_ = chunkMessages_ == 0 ? logTime_ns : std::min(chunkStart_, logTime_ns);
  chunkEnd_ = chunkMessages_ == 0 ? logTime_ns : std::max(chunkEnd_, logTime_ns);
  firstTime_ = messages_ == 0 ? logTime_ns : std::min(firstTime_, logTime_ns);
  lastTime_ = messages_ == 0 ? logTime_ns : std::max(lastTime_, logTime_ns);
  ++chunkMessages_;
  ++messages_;
  ++channel.count;
  if (chunk_.size() >= options_.chunkBytes) closeChunk();
}

// The first message of a channel in a chunk brings its Schema and Channel records along.
void McapWriter::declareInChunk(std::uint16_t channelId, Channel& channel) {
  if (channel.schemaId != 0) {
    Schema& schema = schemas_[channel.schemaId - 1];
    if (schema.chunkSerial != chunkSerial_) {
      chunk_.append(schema.record);
      schema.chunkSerial = chunkSerial_;
    }
  }
  chunk_.append(channel.record);
  channel.chunkSerial = chunkSerial_;
  channel.index.clear();
  chunkChannels_.push_back(channelId);
}

void McapWriter::attach(std::string_view name, std::string_view mediaType, std::uint64_t logTime_ns,
                        std::uint64_t createTime_ns, std::string_view data) {
  checkWritable();
  closeChunk();
  // The data goes out as it is (attachments can be large parts): prefix, data, CRC.
  out_.clear();
  putU8(out_, static_cast<std::uint8_t>(McapOp::Attachment));
  putU64(out_, 8 + 8 + 4 + name.size() + 4 + mediaType.size() + 8 + data.size() + 4);
  putU64(out_, logTime_ns);
  putU64(out_, createTime_ns);
  putString(out_, name);
  putString(out_, mediaType);
  putU64(out_, data.size());
  const std::uint32_t crc =
      mcapCrc32(data, mcapCrc32(std::string_view(out_).substr(kMcapRecordPrefix)));
  std::string tail;
  putU32(tail, crc);
  const std::uint64_t offset = offset_;
  writeOut(out_);
  writeOut(data);
  writeOut(tail);

  const std::size_t start = beginRecord(attachmentIndexes_, McapOp::AttachmentIndex);
  putU64(attachmentIndexes_, offset);
  putU64(attachmentIndexes_, offset_ - offset);
  putU64(attachmentIndexes_, logTime_ns);
  putU64(attachmentIndexes_, createTime_ns);
  putU64(attachmentIndexes_, data.size());
  putString(attachmentIndexes_, name);
  putString(attachmentIndexes_, mediaType);
  endRecord(attachmentIndexes_, start);
  ++attachments_;
}

void McapWriter::metadata(std::string_view name,
                          const std::map<std::string, std::string>& entries) {
  checkWritable();
  closeChunk();
  out_.clear();
  const std::size_t record = beginRecord(out_, McapOp::Metadata);
  putString(out_, name);
  putStringMap(out_, entries);
  endRecord(out_, record);
  const std::uint64_t offset = offset_;
  writeOut(out_);

  const std::size_t start = beginRecord(metadataIndexes_, McapOp::MetadataIndex);
  putU64(metadataIndexes_, offset);
  putU64(metadataIndexes_, out_.size());
  putString(metadataIndexes_, name);
  endRecord(metadataIndexes_, start);
  ++metadataRecords_;
}

void McapWriter::flush() {
  checkWritable();
  closeChunk();
}

// Writes the open chunk, then its message indexes, in one write; records its ChunkIndex.
void McapWriter::closeChunk() {
  if (chunkMessages_ == 0) return;  // a chunk only ever opens with a message
  const std::uint64_t chunkOffset = offset_;
  const std::uint64_t compressed = appendChunkRecord();
  const std::uint64_t chunkLength = out_.size();
  indexOffsets_.clear();
  appendMessageIndexes(indexOffsets_);
  writeOut(out_);

  std::string& ci = chunkIndexes_;
  const std::size_t start = beginRecord(ci, McapOp::ChunkIndex);
  putU64(ci, chunkStart_);
  putU64(ci, chunkEnd_);
  putU64(ci, chunkOffset);
  putU64(ci, chunkLength);
  putString(ci, indexOffsets_);
  putU64(ci, out_.size() - chunkLength);
  putString(ci, "zstd");
  putU64(ci, compressed);
  putU64(ci, chunk_.size());
  endRecord(ci, start);

  ++chunks_;
  ++chunkSerial_;
  chunkMessages_ = 0;
  chunk_.clear();
  chunkChannels_.clear();
}

// The Chunk record into out_, compressed straight into place (no second copy); returns
// the compressed size.
std::uint64_t McapWriter::appendChunkRecord() {
  out_.clear();
  const std::size_t record = beginRecord(out_, McapOp::Chunk);
  putU64(out_, chunkStart_);
  putU64(out_, chunkEnd_);
  putU64(out_, chunk_.size());
  putU32(out_, mcapCrc32(chunk_));
  putString(out_, "zstd");
  const std::size_t sizeAt = out_.size();
  putU64(out_, 0);
  const std::size_t at = out_.size();
  out_.resize(at + ZSTD_compressBound(chunk_.size()));
  const std::size_t n =
      ZSTD_compress2(zstd_, out_.data() + at, out_.size() - at, chunk_.data(), chunk_.size());
  if (ZSTD_isError(n)) fail("cannot write " + path_ + ": zstd: " + ZSTD_getErrorName(n));
  out_.resize(at + n);
  patchU64(out_, sizeAt, n);
  endRecord(out_, record);
  return n;
}

// One MessageIndex per channel of the chunk, right after it, in channel order.
void McapWriter::appendMessageIndexes(std::string& offsets) {
  std::sort(chunkChannels_.begin(), chunkChannels_.end());
  for (const std::uint16_t id : chunkChannels_) {
    putU16(offsets, id);
    putU64(offsets, offset_ + out_.size());
    const auto& entries = channels_[id - 1].index;
    const std::size_t start = beginRecord(out_, McapOp::MessageIndex);
    putU16(out_, id);
    putU32(out_, static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [time, at] : entries) {
      putU64(out_, time);
      putU64(out_, at);
    }
    endRecord(out_, start);
  }
}

void McapWriter::close() {
  if (closed_) return;
  closed_ = true;
  if (!error_.empty()) {
    closeFile();
    throw McapError(error_);
  }
  try {
    closeChunk();
    out_.clear();
    putU8(out_, static_cast<std::uint8_t>(McapOp::DataEnd));
    putU64(out_, 4);
    putU32(out_, dataCrc_);
    writeOut(out_);
    appendSummary();
    writeOut(out_);
  } catch (...) {
    closeFile();
    throw;
  }
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail("cannot write " + path_ + ": " + errnoText(errno));
}

// Summary grouped by opcode, one SummaryOffset per group, Footer, magic: all into out_.
void McapWriter::appendSummary() {
  const std::uint64_t summaryStart = offset_;
  out_.clear();
  std::string offsets;
  auto group = [&](McapOp op, auto&& append) {
    const std::size_t start = out_.size();
    append();
    if (out_.size() == start) return;
    const std::size_t record = beginRecord(offsets, McapOp::SummaryOffset);
    putU8(offsets, static_cast<std::uint8_t>(op));
    putU64(offsets, summaryStart + start);
    putU64(offsets, out_.size() - start);
    endRecord(offsets, record);
  };
  group(McapOp::Schema, [&] {
    for (const Schema& s : schemas_) out_.append(s.record);
  });
  group(McapOp::Channel, [&] {
    for (const Channel& c : channels_) out_.append(c.record);
  });
  group(McapOp::Statistics, [&] {
    const std::size_t start = beginRecord(out_, McapOp::Statistics);
    putU64(out_, messages_);
    putU16(out_, static_cast<std::uint16_t>(schemas_.size()));
    putU32(out_, static_cast<std::uint32_t>(channels_.size()));
    putU32(out_, static_cast<std::uint32_t>(attachments_));
    putU32(out_, static_cast<std::uint32_t>(metadataRecords_));
    putU32(out_, static_cast<std::uint32_t>(chunks_));
    putU64(out_, firstTime_);
    putU64(out_, lastTime_);
    std::string counts;
    for (std::size_t i = 0; i < channels_.size(); ++i) {
      putU16(counts, static_cast<std::uint16_t>(i + 1));
      putU64(counts, channels_[i].count);
    }
    putString(out_, counts);
    endRecord(out_, start);
  });
  group(McapOp::ChunkIndex, [&] { out_.append(chunkIndexes_); });
  group(McapOp::AttachmentIndex, [&] { out_.append(attachmentIndexes_); });
  group(McapOp::MetadataIndex, [&] { out_.append(metadataIndexes_); });
  const std::uint64_t summaryOffsetStart = summaryStart + out_.size();
  out_.append(offsets);
  putU8(out_, static_cast<std::uint8_t>(McapOp::Footer));
  putU64(out_, 20);
  putU64(out_, summaryStart);
  putU64(out_, summaryOffsetStart);
  putU32(out_, mcapCrc32(out_));  // the summary through the footer's summary_offset_start
  out_.append(kMcapMagic);
}

void McapWriter::checkWritable() const {
  if (!error_.empty()) throw McapError(error_ + " (the writer stopped at that error)");
  if (closed_) throw McapError(path_ + ": the MCAP writer is closed");
}

void McapWriter::writeOut(std::string_view bytes) {
  dataCrc_ = mcapCrc32(bytes, dataCrc_);  // only its value at DataEnd is used
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail("cannot write " + path_ + ": " + errnoText(errno));
    bytes.remove_prefix(static_cast<std::size_t>(n));
    offset_ += static_cast<std::uint64_t>(n);
  }
}

void McapWriter::fail(const std::string& message) {
  if (error_.empty()) error_ = message;
  throw McapError(message);
}

void McapWriter::closeFile() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace hg::session
