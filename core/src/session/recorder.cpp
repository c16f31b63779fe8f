#include "hapticgrasp/session/recorder.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"
#include "hapticgrasp/session/foxglove_messages.hpp"
#include "hapticgrasp/session/model_swap_message.hpp"
#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/tick_message.hpp"

namespace hg::session {
namespace {

std::uint64_t wallNs() {
  timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000u + static_cast<std::uint64_t>(ts.tv_nsec);
}
std::uint64_t monotonicNs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000u + static_cast<std::uint64_t>(ts.tv_nsec);
}

enum Channel { kTick, kEvent, kNote, kFrame, kPartScene, kHandScene, kModel };

std::size_t ringCapacity(double rate_hz, double seconds) {
  return static_cast<std::size_t>(std::ceil(std::clamp(rate_hz, 50.0, 10000.0) * std::max(0.1, seconds)));
}

}  // namespace

Recorder::Recorder(const std::filesystem::path& path, SessionDescription description, grasp::ScenePtr scene)
    : Recorder(path, std::move(description), std::move(scene), Options{}) {}

Recorder::Recorder(const std::filesystem::path& path, SessionDescription description, grasp::ScenePtr scene,
                   const Options& options)
    : path_(path),
      description_(std::move(description)),
      scene_(std::move(scene)),
      options_(options),
      ring_(std::make_shared<servo::TickRecordRing>(ringCapacity(description_.rate_hz, options.ringSeconds))) {
  if (!scene_) throw std::invalid_argument("recorder: no scene");
  if (description_.parts.size() != scene_->size())
    throw std::invalid_argument("recorder: the description has " + std::to_string(description_.parts.size()) +
                                " parts, the scene " + std::to_string(scene_->size()));
  std::error_code ignored;
  if (path_.has_parent_path()) std::filesystem::create_directories(path_.parent_path(), ignored);
  options_.mcap.chunkSeconds = std::min(options_.mcap.chunkSeconds, options_.flushEvery_s);
  writer_ = std::make_unique<McapWriter>(path_.string(), options_.mcap);
  names_ = description_.partNames();
  for (const RecordedPart& p : description_.parts) poses_.push_back(p.initialPose);
  publicationsWritten_ = description_.scenePublications;
  writeHeader();
}

Recorder::~Recorder() { stop(); }

// The description, one attachment per distinct shape, the schemas and channels.
void Recorder::writeHeader() {
  writer_->metadata(kSessionMetadata, {{"json", toJson(description_)},
                                       {"document", description_.document},
                                       {"software", description_.software},
                                       {"method", description_.method},
                                       {"device", description_.device.name}});
  std::set<std::string> attached;
  for (const RecordedPart& p : description_.parts)
    if (!p.attachment.empty() && attached.insert(p.attachment).second)
      writer_->attach(p.attachment, kBrepMediaType, 0, wallNs(), p.brep);
  const std::uint16_t tick = writer_->addSchema("hapticgrasp.Tick", "protobuf", tickSchema());
  const std::uint16_t log = writer_->addSchema("foxglove.Log", "protobuf", logSchema());
  const std::uint16_t frames = writer_->addSchema("foxglove.FrameTransforms", "protobuf", frameTransformsSchema());
  const std::uint16_t scene = writer_->addSchema("foxglove.SceneUpdate", "protobuf", sceneUpdateSchema());
  tickChannel_ = writer_->addChannel(tick, kTickTopic, "protobuf");
  eventChannel_ = writer_->addChannel(log, kEventTopic, "protobuf");
  noteChannel_ = writer_->addChannel(log, kAnnotationTopic, "protobuf");
  frameChannel_ = writer_->addChannel(frames, kFrameTopic, "protobuf");
  partChannel_ = writer_->addChannel(scene, kPartSceneTopic, "protobuf");
  handChannel_ = writer_->addChannel(scene, kHandSceneTopic, "protobuf");
  const std::uint16_t swap = writer_->addSchema(std::string(kModelSwapSchemaName), "protobuf", modelSwapSchema());
  modelChannel_ = writer_->addChannel(swap, kModelTopic, "protobuf");
  writer_->flush();
}

void Recorder::start() {
  if (running_.exchange(true)) throw std::logic_error("recorder: start() called twice");
  // Loop time 0 is about now (the loop starts right after); every message's time is this
  // wall-clock origin plus the servo's monotonic loop time: one clock, no zero stamps.
  epoch_ns_ = wallNs();
  thread_ = std::thread([this] { run(); });
}

void Recorder::stop() noexcept {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (writer_) {
    try {
      writer_->close();
    } catch (const std::exception& e) {
      fail(e.what());
    }
  }
}

void Recorder::annotate(double time_s, std::string text, std::string part) {
  const std::lock_guard<std::mutex> lock(mutex_);
  notes_.push_back({time_s, std::move(text), std::move(part)});
}

Recorder::Status Recorder::status() const {
  Status s;
  s.path = path_.string();
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    s.error = error_;
  }
  s.recording = running_.load() && !stop_.load() && s.error.empty();
  s.ticks = ticks_.load();
  s.dropped = ring_->dropped();
  s.messages = messages_.load();
  s.bytes = bytes_.load();
  s.annotations = annotations_.load();
  s.duration_s = duration_s_.load();
  return s;
}

void Recorder::fail(const std::string& why) noexcept {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (error_.empty()) error_ = "recording stopped: " + why;
}

std::uint64_t Recorder::logTime(double loopTime_s) const noexcept {
  return epoch_ns_ + static_cast<std::uint64_t>(std::llround(std::max(0.0, loopTime_s) * 1e9));
}

// Drains the ring until stopped (then drains what is left), flushing a chunk at least
// every flushEvery_s of wall time. A write error ends the thread; the servo goes on.
void Recorder::run() noexcept {
  try {
    servo::TickRecord record;
    std::uint64_t lastFlush = monotonicNs();
    const auto flushEvery = static_cast<std::uint64_t>(options_.flushEvery_s * 1e9);
    for (;;) {
      const bool stopping = stop_.load(std::memory_order_acquire);
      int n = 0;
      while (n < 4096 && ring_->pop(record)) {
        writeModelSwaps(record);
        writeTick(record);
        ++n;
      }
      writeNotes();
      if (!modelsWritten_ && haveViewer_) writePartModels(lastViewer_ns_);
      if (monotonicNs() - lastFlush >= flushEvery) {
        writer_->flush();
        lastFlush = monotonicNs();
      }
      messages_.store(writer_->messages(), std::memory_order_relaxed);
      bytes_.store(writer_->bytes(), std::memory_order_relaxed);
      if (stopping && ring_->size() == 0) break;
      if (n == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    // What the reader cannot tell from the ticks alone: how many the ring dropped.
    writer_->metadata(kRecordingMetadata, {{"ticks", std::to_string(ticks_.load())},
                                           {"dropped_records", std::to_string(ring_->dropped())},
                                           {"annotations", std::to_string(annotations_.load())}});
    writer_->close();
    messages_.store(writer_->messages());
    bytes_.store(writer_->bytes());
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

void Recorder::writeTick(const servo::TickRecord& r) {
  const std::uint64_t t = logTime(r.time_s);
  encodeTick(r, buffer_);
  writer_->write(tickChannel_, sequence_[kTick]++, t, t, buffer_);
  writeEvents(r, t);
  trackPoses(r, t);
  if (!haveViewer_ || t - lastViewer_ns_ >= static_cast<std::uint64_t>(1e9 / options_.viewerRate_hz))
    writeViewer(r, t);
  ticks_.fetch_add(1, std::memory_order_relaxed);
  duration_s_.store(r.time_s, std::memory_order_relaxed);
}

// The models the scene published before this tick began and after those already written:
// each part's current model (a later swap of the same part may already show; replay then
// publishes it a little early, which the part's stand-in box made harmless). When the
// scene's log has wrapped past what was written, every part is written.
void Recorder::writeModelSwaps(const servo::TickRecord& r) {
  if (r.scenePublications <= publicationsWritten_) return;
  const std::uint64_t t = logTime(r.time_s);
  for (; publicationsWritten_ < r.scenePublications; ++publicationsWritten_) {
    const int part = scene_->publishedPart(publicationsWritten_);
    if (part >= 0) {
      writeModelSwap(publicationsWritten_, part, t);
      continue;
    }
    for (std::size_t i = 0; i < scene_->size(); ++i) writeModelSwap(publicationsWritten_, static_cast<int>(i), t);
    publicationsWritten_ = r.scenePublications;
    return;
  }
}

void Recorder::writeModelSwap(std::uint64_t publication, int part, std::uint64_t t) {
  const grasp::ScenePart& models = scene_->part(static_cast<std::size_t>(part));
  ModelSwap swap{publication, part, describePart(models, names_[static_cast<std::size_t>(part)])};
  swap.model.initialPose = description_.parts[static_cast<std::size_t>(part)].initialPose;
  encodeModelSwap(swap, buffer_);
  writer_->write(modelChannel_, sequence_[kModel]++, t, t, buffer_);
  if (!modelsWritten_ || !models.model) return;
  const PartMesh mesh = partMesh(*models.model, names_[static_cast<std::size_t>(part)], options_.meshDeflection_m);
  encodePartModels(std::span<const PartMesh>(&mesh, 1), t, buffer_);  // replaces the viewers' stand-in box
  writer_->write(partChannel_, sequence_[kPartScene]++, t, t, buffer_);
}

void Recorder::writeEvents(const servo::TickRecord& r, std::uint64_t t) {
  if (r.events == 0 && r.state == r.stateBefore) return;
  std::string text = servo::eventsText(r.events);
  if (r.state != r.stateBefore)
    text += (text.empty() ? "" : "; ") + std::string(grasp::toString(r.stateBefore)) + " -> " + grasp::toString(r.state);
  const bool fault = r.events & servo::kWatchdogTrip;
  const std::string part = r.graspedPart >= 0 && static_cast<std::size_t>(r.graspedPart) < names_.size()
                               ? names_[static_cast<std::size_t>(r.graspedPart)]
                               : "";
  encodeLog(t, fault ? kLogWarning : kLogInfo, part, text, buffer_);
  writer_->write(eventChannel_, sequence_[kEvent]++, t, t, buffer_);
}

// Every part's pose, from the moving parts of each tick (a reset puts all back); the
// viewers get every part at the start and a part's frame when it stops moving.
void Recorder::trackPoses(const servo::TickRecord& r, std::uint64_t t) {
  const bool reset = (r.commands & servo::kCommandReset) || (r.events & servo::kWatchdogTrip);
  if (reset)
    for (std::size_t i = 0; i < poses_.size(); ++i) poses_[i] = description_.parts[i].initialPose;
  const int n = std::min(r.movingCount, servo::TickRecord::kMaxMoving);
  std::vector<int> moving(r.movingPart, r.movingPart + n);
  for (int k = 0; k < n; ++k)
    if (r.movingPart[k] >= 0 && static_cast<std::size_t>(r.movingPart[k]) < poses_.size())
      poses_[static_cast<std::size_t>(r.movingPart[k])] = r.movingPose[k];
  bool stopped = false;
  for (const int part : wasMoving_) stopped |= std::find(moving.begin(), moving.end(), part) == moving.end();
  wasMoving_ = std::move(moving);
  if (r.tick == 1 || reset || stopped || sequence_[kFrame] == 0) {
    encodePartFrames(poses_, names_, t, buffer_);
    writer_->write(frameChannel_, sequence_[kFrame]++, t, t, buffer_);
  }
}

void Recorder::writeViewer(const servo::TickRecord& r, std::uint64_t t) {
  encodeHandFrames(r, names_, t, buffer_);
  writer_->write(frameChannel_, sequence_[kFrame]++, t, t, buffer_);
  encodeHandScene(r, grasp::toString(r.state), t, buffer_);
  writer_->write(handChannel_, sequence_[kHandScene]++, t, t, buffer_);
  lastViewer_ns_ = t;
  haveViewer_ = true;
}

// The parts' shapes for viewers, once, after the first tick (tessellating takes the writer
// thread a while; the ring holds the ticks meanwhile). Shared models are tessellated once.
void Recorder::writePartModels(std::uint64_t t) {
  std::vector<PartMesh> meshes;
  meshes.reserve(scene_->size());
  std::map<const geometry::PartModel*, std::size_t> done;
  for (std::size_t i = 0; i < scene_->size(); ++i) {
    const grasp::ScenePart& part = scene_->part(i);
    if (!part.model) {
      meshes.push_back(boxMesh(part.bounds, names_[i]));
      continue;
    }
    const auto [it, fresh] = done.emplace(part.model.get(), meshes.size());
    if (fresh) {
      meshes.push_back(partMesh(*part.model, names_[i], options_.meshDeflection_m));
    } else {
      PartMesh copy = meshes[it->second];
      copy.name = names_[i];
      meshes.push_back(std::move(copy));
    }
  }
  encodePartModels(meshes, t, buffer_);
  writer_->write(partChannel_, sequence_[kPartScene]++, t, t, buffer_);
  modelsWritten_ = true;
}

void Recorder::writeNotes() {
  std::vector<Note> notes;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    notes.swap(notes_);
  }
  for (const Note& n : notes) {
    const std::uint64_t t = logTime(n.time_s);
    encodeLog(t, kLogInfo, n.part, n.text, buffer_);
    writer_->write(noteChannel_, sequence_[kNote]++, t, t, buffer_);
    annotations_.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace hg::session
