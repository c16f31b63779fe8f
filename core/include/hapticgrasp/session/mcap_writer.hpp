#pragma once
// Writes an MCAP file (see mcap_format.hpp for why it is hand-written): messages in
// zstd-compressed chunks, each followed by its message indexes, then at close the summary
// (schemas, channels, statistics, chunk/attachment/metadata indexes), summary offsets and
// footer, laid out as the reference reader (@mcap/core McapIndexedReader) requires.
//
// Crash safety: every chunk is handed to the OS when it closes, and a chunk closes at
// `chunkBytes` of records or when a message is `chunkSeconds` past the chunk's first one.
// Each chunk repeats the Schema and Channel records its messages use, so a file cut short
// (killed recorder, full disk) is self-describing from its start, and a chunk lost to
// corruption does not orphan the channels of later ones. A recorder whose messages may
// pause calls flush() on a timer to keep the "at most about a second lost" promise.
//
// Not thread-safe: one writer thread owns it (never the servo thread: it allocates while
// warming up and blocks on the disk).
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/session/mcap_format.hpp"

struct ZSTD_CCtx_s;

namespace hg::session {

// McapWriter::Options (at namespace scope so that it can be a defaulted argument).
struct McapWriterOptions {
  std::size_t chunkBytes = 1 << 20;  // close a chunk once its records reach this size
  double chunkSeconds = 1.0;  // ... or a message comes this long after its first (<= 0: never)
  int zstdLevel = 3;
  std::string profile;  // the Header's profile ("" or e.g. "ros2")
  std::string library = "hapticgrasp";
};

class McapWriter {
 public:
  using Options = McapWriterOptions;

  // Creates (truncates) the file and writes the magic and Header at once.
  // Throws McapError("cannot write <path>: <strerror>").
  explicit McapWriter(const std::string& path, Options options = {});
  ~McapWriter();  // close()s; never throws (a failure is lost: call close() to see it)
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Ids count from 1. A schema id of 0 in addChannel means "no schema".
  std::uint16_t addSchema(std::string_view name, std::string_view encoding, std::string_view data);
  std::uint16_t addChannel(std::uint16_t schemaId, std::string_view topic,
                           std::string_view messageEncoding,
                           const std::map<std::string, std::string>& metadata = {});

  void write(std::uint16_t channel, std::uint32_t sequence, std::uint64_t logTime_ns,
             std::uint64_t publishTime_ns, std::string_view data);
  // Attachments and metadata go between chunks: each closes the open chunk first.
  void attach(std::string_view name, std::string_view mediaType, std::uint64_t logTime_ns,
              std::uint64_t createTime_ns, std::string_view data);
  void metadata(std::string_view name, const std::map<std::string, std::string>& entries);

  // Writes the open chunk (if it holds anything) and its message indexes to the OS.
  void flush();
  // flush, DataEnd, summary, summary offsets, footer, magic; closes the file. Idempotent.
  void close();

  // Any write error (ENOSPC, EIO, ...) throws McapError naming the file and the errno
  // text; from then on every call that would write throws again.
  std::uint64_t bytes() const { return offset_; }  // handed to the OS so far
  std::uint64_t messages() const { return messages_; }
  std::uint64_t chunks() const { return chunks_; }

 private:
  struct Channel {
    std::uint16_t schemaId = 0;
    std::string record;  // the serialized Channel record, for chunks and the summary
    std::uint64_t count = 0;
    std::uint64_t chunkSerial = 0;  // == chunkSerial_: declared in the open chunk
    std::vector<std::pair<std::uint64_t, std::uint64_t>> index;  // (log time, offset)
  };
  struct Schema {
    std::string record;
    std::uint64_t chunkSerial = 0;
  };

  void checkWritable() const;
  void declareInChunk(std::uint16_t channelId, Channel& channel);
  void closeChunk();
  std::uint64_t appendChunkRecord();
  void appendMessageIndexes(std::string& chunkIndexOffsets);
  void appendSummary();
  void writeOut(std::string_view bytes);
  void fail(const std::string& message);
  void closeFile();

  std::string path_;
  Options options_;
  std::uint64_t chunkNs_ = 0;  // 0: no time limit
  int fd_ = -1;
  ZSTD_CCtx_s* zstd_ = nullptr;
  bool closed_ = false;
  std::string error_;  // the first write error; non-empty = failed

  std::uint64_t offset_ = 0;     // bytes handed to the OS
  std::uint32_t dataCrc_ = 0;    // CRC of everything written before DataEnd
  std::vector<Schema> schemas_;  // by id - 1
  std::vector<Channel> channels_;

  // The open chunk.
  std::string chunk_;  // uncompressed records
  std::uint64_t chunkSerial_ = 1;
  std::uint64_t chunkMessages_ = 0, chunkStart_ = 0, chunkEnd_ = 0;
  std::vector<std::uint16_t> chunkChannels_;  // channels with messages in it

  std::string out_;           // the bytes of the next write (a chunk and its indexes), reused
  std::string indexOffsets_;  // Map<u16, u64>: channel -> its MessageIndex record's offset

  // Summary material, serialized as it comes.
  std::string chunkIndexes_, attachmentIndexes_, metadataIndexes_;
  std::uint64_t messages_ = 0, chunks_ = 0, attachments_ = 0, metadataRecords_ = 0;
  std::uint64_t firstTime_ = 0, lastTime_ = 0;
};

}  // namespace hg::session
