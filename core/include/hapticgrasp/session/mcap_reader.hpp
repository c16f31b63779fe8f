#pragma once
// Reads an MCAP file (see mcap_format.hpp for why it is hand-written) as a stream: records
// forward from the start, one chunk in memory at a time, so files larger than RAM read.
//
// Made for recordings that may have been cut short (killed recorder, full disk) or damaged:
// a truncated file reads up to its last complete chunk and says so in the summary's
// warnings; a damaged chunk (CRC, zstd, lengths) is skipped with a warning and the others
// still read; a hostile file (absurd lengths, decompression bombs, garbage) gets warnings
// and a partial read within `Limits`, never a crash, a hang or unbounded memory. Only
// "cannot open", "not an MCAP file" and I/O errors throw McapError.
//
// Every CRC is checked where the file has one (chunks, attachments, summary). The data
// section CRC is not: checking it would mean reading the message indexes the reader skips,
// and every part it uses has its own CRC or sits in a CRC-checked chunk.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/session/mcap_format.hpp"

struct ZSTD_DCtx_s;

namespace hg::session {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name, encoding, data;
  bool operator==(const McapSchema&) const = default;
};

struct McapChannel {
  std::uint16_t id = 0, schemaId = 0;  // schemaId 0: no schema
  std::string topic, messageEncoding;
  std::map<std::string, std::string> metadata;
  bool operator==(const McapChannel&) const = default;
};

// A message as the callback sees it: `data` points into the reader's chunk buffer and
// lives until the callback returns.
struct McapMessageView {
  std::uint16_t channel = 0;
  std::uint32_t sequence = 0;
  std::uint64_t logTime_ns = 0, publishTime_ns = 0;
  std::string_view data;
};

struct McapAttachment {
  std::string name, mediaType;
  std::uint64_t logTime_ns = 0, createTime_ns = 0;
  std::uint64_t offset = 0;     // of its record in the file
  std::uint64_t dataBytes = 0;  // as the record declares it
  bool dataLoaded = false;      // false: skipped on request, over the limit, or a bad CRC
  std::string data;
};

struct McapMetadata {
  std::string name;
  std::map<std::string, std::string> entries;
};

// A chunk as the summary's Chunk Index describes it.
struct McapChunkInfo {
  std::uint64_t startTime_ns = 0, endTime_ns = 0;
  std::uint64_t offset = 0, length = 0;  // the Chunk record, prefix included
  std::uint64_t compressedBytes = 0, uncompressedBytes = 0;
  std::string compression;
};

// What one read found.
struct McapSummary {
  bool complete = false;  // closed properly: DataEnd, a valid summary and footer
  std::uint64_t messages = 0;
  std::uint64_t firstTime_ns = 0, lastTime_ns = 0;  // of the messages read
  std::uint64_t lastGoodTime_ns = 0;                // the latest log time before anything was lost
  std::uint64_t bytesRecovered = 0;                 // the file up to here read as intact records
  std::uint64_t fileBytes = 0;
  std::uint64_t chunks = 0, chunksSkipped = 0;
  std::map<std::uint16_t, std::uint64_t> perChannel;  // messages read per channel id
  std::vector<std::string> warnings;  // at most ~100: a garbage file cannot flood memory
};

// What a time-window read did.
struct McapWindowRead {
  bool indexed = false;  // chunks found through the summary's index, not by a linear scan
  std::uint64_t messages = 0;
  std::uint64_t chunksRead = 0;  // chunks decompressed
  std::uint64_t chunksInFile = 0;
  std::vector<std::string> warnings;
};

// McapReader::Limits: what one file may make the reader hold in memory. Each record is
// also bounded by the bytes left in the file.
struct McapReaderLimits {
  std::uint64_t maxRecordBytes = 256ull << 20;        // one record (a chunk's compressed bytes)
  std::uint64_t maxChunkUncompressed = 256ull << 20;  // a chunk's declared uncompressed size
  double maxCompressionRatio = 1000;                  // declared uncompressed / compressed ...
  std::uint64_t ratioCheckAbove = 16ull << 20;        // ... for chunks declaring more than this
  std::uint64_t maxAttachmentBytes = 256ull << 20;    // larger ones are listed without data
  std::uint64_t maxSummaryBytes = 256ull << 20;
};

class McapReader {
 public:
  using Limits = McapReaderLimits;
  using MessageCallback = std::function<void(const McapMessageView&)>;

  // Opens the file, checks its magic and reads its summary (index) if it has a valid one.
  // Throws McapError: "cannot open <path>: <strerror>", "<path> is not an MCAP file".
  explicit McapReader(const std::string& path, Limits limits = {});
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  // Reads the whole file forward, calling onMessage per message in file order; fills
  // schemas, channels, attachments (without their data if !attachmentData) and metadata.
  McapSummary scan(const MessageCallback& onMessage = {}, bool attachmentData = true);

  // The messages with start_ns <= log time <= end_ns, in file order (time order for files
  // McapWriter wrote). Reads only the chunks the summary's index says overlap the window
  // when the file has a valid index; scans the file otherwise.
  McapWindowRead readMessages(std::uint64_t start_ns, std::uint64_t end_ns,
                              const MessageCallback& onMessage);

  bool indexed() const { return indexed_; }  // a valid summary with its chunk index
  const std::vector<McapChunkInfo>& chunkIndex() const { return chunkIndex_; }
  std::uint64_t fileBytes() const { return size_; }
  const std::string& profile() const { return profile_; }
  const std::string& library() const { return library_; }
  // From the summary at open, completed by every read.
  const std::map<std::uint16_t, McapSchema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, McapChannel>& channels() const { return channels_; }
  // Filled by scan().
  const std::vector<McapAttachment>& attachments() const { return attachments_; }
  const std::vector<McapMetadata>& metadata() const { return metadata_; }

 private:
  struct Pass;
  struct ChunkHead;

  void readAt(std::uint64_t offset, std::uint64_t bytes, std::string& out) const;
  void readIndex();
  bool parseSummary(std::string_view summary, std::uint64_t summaryStart);
  void linearPass(Pass& pass);
  bool handleRecord(Pass& pass, std::uint64_t pos, std::uint8_t op, std::uint64_t length);
  bool handleChunk(Pass& pass, std::uint64_t pos, std::uint64_t length);
  void readIndexedChunk(Pass& pass, const McapChunkInfo& chunk);
  void readChunk(Pass& pass, std::uint64_t pos, std::string_view content);
  bool decompress(Pass& pass, std::uint64_t pos, const ChunkHead& head, std::string_view compressed,
                  std::string_view& records);
  void readChunkRecords(Pass& pass, std::uint64_t pos, std::string_view records);
  void readAttachment(Pass& pass, std::uint64_t pos, std::uint64_t length);
  void addSchema(Pass& pass, std::uint64_t pos, std::string_view content);
  void addChannel(Pass& pass, std::uint64_t pos, std::string_view content);
  void deliver(Pass& pass, const McapMessageView& message) const;

  std::string path_;
  Limits limits_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  ZSTD_DCtx_s* zstd_ = nullptr;

  std::string profile_, library_;
  std::map<std::uint16_t, McapSchema> schemas_;
  std::map<std::uint16_t, McapChannel> channels_;
  std::vector<McapAttachment> attachments_;
  std::vector<McapMetadata> metadata_;

  // From the summary, read at open.
  bool footerFound_ = false;
  bool indexed_ = false;
  std::uint64_t dataEnd_ = 0;              // where the summary says the DataEnd record is
  std::vector<McapChunkInfo> chunkIndex_;  // sorted by offset
  bool haveStatistics_ = false;
  std::uint64_t statisticsMessages_ = 0;
  std::vector<std::string> indexWarnings_;

  std::string record_;                   // the record being read, reused
  std::unique_ptr<char[]> chunkBuffer_;  // decompressed records, reused (not zero-filled)
  std::uint64_t chunkCapacity_ = 0;
};

}  // namespace hg::session
