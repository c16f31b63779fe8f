#pragma once
// Records a servo session into an MCAP file, never on the servo thread's time: the loop's
// record stage pushes one fixed-size TickRecord per tick into ring(); this class's writer
// thread drains it, serialises (protobuf), compresses (zstd chunks) and writes.
//
// Channels:
//   /hapticgrasp/tick         hapticgrasp.Tick, every tick (replay re-runs these)
//   /hapticgrasp/events       foxglove.Log, the ticks that raised events or changed state
//   /hapticgrasp/annotations  foxglove.Log, reviewers' notes (name = the part under the hand)
//   /tf                       foxglove.FrameTransforms: fingertips, wrist and moving parts
//                             at viewerRate_hz; every part at the start and when one stops
//   /scene/parts              foxglove.SceneUpdate: each part's tessellated shape, once
//   /scene/hand               foxglove.SceneUpdate: fingertips, force arrows, the state, at viewerRate_hz
//   /hapticgrasp/models       hapticgrasp.ModelSwap: a part's models published during the
//                             session (model_swap_message.hpp), written before the first tick
//                             that saw them, so that replay can publish them at the same tick
// plus the session's description (Metadata kSessionMetadata) and each distinct shape's
// BREP (attachments), so that a recording is self-contained.
//
// Crash safety: the writer closes a chunk at least every flushEvery_s (of session time and
// of wall time), so a killed recording loses at most about that much. A write error (disk
// full) stops the recording with status().error saying why; the haptic session goes on
// (the ring then fills and counts its drops).
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hapticgrasp/scene/scene.hpp"
#include "hapticgrasp/servo/tick_record.hpp"
#include "hapticgrasp/session/mcap_writer.hpp"
#include "hapticgrasp/session/session_description.hpp"

namespace hg::session {

inline constexpr std::string_view kTickTopic = "/hapticgrasp/tick";
inline constexpr std::string_view kEventTopic = "/hapticgrasp/events";
inline constexpr std::string_view kAnnotationTopic = "/hapticgrasp/annotations";
inline constexpr std::string_view kFrameTopic = "/tf";
inline constexpr std::string_view kPartSceneTopic = "/scene/parts";
inline constexpr std::string_view kHandSceneTopic = "/scene/hand";

class Recorder {
 public:
  struct Options {
    double viewerRate_hz = 100;       // the Foxglove channels, at most this often
    double ringSeconds = 2;           // ticks the ring holds, at the session's rate
    double flushEvery_s = 1;          // a chunk reaches the disk at least this often
    double meshDeflection_m = 0.2e-3; // the parts' tessellation for viewers
    McapWriter::Options mcap;
  };
  struct Status {
    bool recording = false;           // the writer runs and every write so far succeeded
    std::string path;
    std::string error;                // why recording stopped early; "" if it did not
    std::uint64_t ticks = 0;          // tick records written
    std::uint64_t dropped = 0;        // tick records lost because the ring was full
    std::uint64_t messages = 0;       // MCAP messages, every channel
    std::uint64_t bytes = 0;          // file size so far
    std::uint64_t annotations = 0;
    double duration_s = 0;            // loop time of the last tick written
  };

  // Creates `path` (its directory too) and writes the description and the parts' BREPs.
  // Throws McapError when the file cannot be created or written.
  Recorder(const std::filesystem::path& path, SessionDescription description, grasp::ScenePtr scene,
           const Options& options);
  Recorder(const std::filesystem::path& path, SessionDescription description, grasp::ScenePtr scene);
  ~Recorder();  // stop()s
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Give it to ServoLoop::record() before the loop starts.
  const std::shared_ptr<servo::TickRecordRing>& ring() const noexcept { return ring_; }

  void start();  // the writer thread; before the loop starts
  // A reviewer's note at loop time `time_s` (any thread but the servo's).
  void annotate(double time_s, std::string text, std::string part);
  // Writes what the ring still holds, closes the file. Idempotent; never throws.
  void stop() noexcept;

  Status status() const;
  const SessionDescription& description() const noexcept { return description_; }

 private:
  struct Note {
    double time_s;
    std::string text, part;
  };
  void run() noexcept;
  void writeHeader();
  void writeTick(const servo::TickRecord& record);
  void writeEvents(const servo::TickRecord& record, std::uint64_t time_ns);
  void trackPoses(const servo::TickRecord& record, std::uint64_t time_ns);
  void writeViewer(const servo::TickRecord& record, std::uint64_t time_ns);
  void writePartModels(std::uint64_t time_ns);
  void writeModelSwaps(const servo::TickRecord& record);
  void writeModelSwap(std::uint64_t publication, int part, std::uint64_t time_ns);
  void writeNotes();
  std::uint64_t logTime(double loopTime_s) const noexcept;
  void fail(const std::string& why) noexcept;

  std::filesystem::path path_;
  SessionDescription description_;
  grasp::ScenePtr scene_;
  Options options_;
  std::shared_ptr<servo::TickRecordRing> ring_;
  std::unique_ptr<McapWriter> writer_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, running_{false};
  std::uint64_t epoch_ns_ = 0;      // wall time of loop time 0 (one clock for every message)

  // Writer-thread data.
  std::uint16_t tickChannel_ = 0, eventChannel_ = 0, noteChannel_ = 0, frameChannel_ = 0, partChannel_ = 0,
                handChannel_ = 0, modelChannel_ = 0;
  std::uint32_t sequence_[8] = {};
  std::uint64_t publicationsWritten_ = 0;  // the scene's publications recorded so far
  std::string buffer_;
  std::vector<std::string> names_;
  std::vector<grasp::PartPose> poses_;
  std::vector<int> wasMoving_;
  std::uint64_t lastViewer_ns_ = 0;
  bool modelsWritten_ = false, haveViewer_ = false;

  mutable std::mutex mutex_;        // notes_ and the status strings
  std::vector<Note> notes_;
  std::string error_;
  std::atomic<std::uint64_t> ticks_{0}, annotations_{0}, messages_{0}, bytes_{0};
  std::atomic<double> duration_s_{0};
};

}  // namespace hg::session
