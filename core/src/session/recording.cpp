#include "hapticgrasp/session/recording.hpp"

#include <nlohmann/json.hpp>

#include "hapticgrasp/session/foxglove_messages.hpp"
#include "hapticgrasp/session/mcap_reader.hpp"
#include "hapticgrasp/session/recorder.hpp"

namespace hg::session {
namespace {

const McapAttachment* findAttachment(const McapReader& reader, const std::string& name) {
  for (const McapAttachment& a : reader.attachments())
    if (a.name == name) return &a;
  return nullptr;
}

double seconds(std::uint64_t t, std::uint64_t origin) { return t > origin ? 1e-9 * static_cast<double>(t - origin) : 0.0; }

}  // namespace

SessionDescription readDescription(const McapReader& reader, bool withShapes) {
  for (const McapMetadata& m : reader.metadata()) {
    if (m.name != kSessionMetadata) continue;
    const auto json = m.entries.find("json");
    if (json == m.entries.end()) throw SessionError("recording: the session metadata has no 'json' entry");
    SessionDescription d = sessionFromJson(json->second);
    if (!withShapes) return d;
    for (RecordedPart& p : d.parts) {
      if (p.attachment.empty()) continue;
      const McapAttachment* a = findAttachment(reader, p.attachment);
      if (!a || !a->dataLoaded)
        throw SessionError("recording: part '" + p.name + "': its shape (" + p.attachment + ") is " +
                           (a ? "damaged" : "missing"));
      p.brep = a->data;
    }
    return d;
  }
  throw SessionError("recording: no session description (metadata '" + std::string(kSessionMetadata) +
                     "'): not a HapticGrasp recording");
}

RecordingInfo readRecordingInfo(const std::string& path) {
  McapReader reader(path);
  RecordingInfo info;
  struct Note {
    std::uint64_t t;
    Annotation a;
  };
  std::vector<Note> notes;
  const McapSummary s = reader.scan(
      [&](const McapMessageView& m) {
        const auto channel = reader.channels().find(m.channel);
        if (channel == reader.channels().end() || channel->second.topic != kAnnotationTopic) return;
        LogEntry log;
        if (decodeLog(m.data, log)) notes.push_back({m.logTime_ns, {0, log.message, log.name}});
      },
      /*attachmentData=*/false);
  info.description = readDescription(reader, /*withShapes=*/false);
  info.complete = s.complete;
  info.firstTime_ns = s.firstTime_ns;
  info.duration_s = seconds(s.lastTime_ns, s.firstTime_ns);
  info.lastGood_s = seconds(s.lastGoodTime_ns, s.firstTime_ns);
  info.messages = s.messages;
  info.bytes = s.fileBytes;
  info.warnings = s.warnings;
  for (const auto& [id, count] : s.perChannel) {
    const auto channel = reader.channels().find(id);
    info.topics[channel == reader.channels().end() ? "channel " + std::to_string(id) : channel->second.topic] += count;
  }
  for (Note& n : notes) {
    n.a.time_s = seconds(n.t, s.firstTime_ns);
    info.annotations.push_back(std::move(n.a));
  }
  for (const McapMetadata& m : reader.metadata()) {
    if (m.name != kRecordingMetadata) continue;
    const auto dropped = m.entries.find("dropped_records");
    if (dropped != m.entries.end()) {
      info.droppedRecords = std::strtoull(dropped->second.c_str(), nullptr, 10);
      info.droppedKnown = true;
    }
    const auto error = m.entries.find("error");
    if (error != m.entries.end()) info.recorderError = error->second;
  }
  if (!info.complete)
    info.warnings.push_back("the recording was cut short: " + std::to_string(info.lastGood_s) +
                            " s recovered (" + std::to_string(s.bytesRecovered) + " of " +
                            std::to_string(s.fileBytes) + " bytes)");
  if (info.droppedKnown && info.droppedRecords > 0)
    info.warnings.push_back(std::to_string(info.droppedRecords) + " tick records were dropped (the writer fell behind)");
  if (!info.recorderError.empty()) info.warnings.push_back(info.recorderError);
  return info;
}

std::string toJson(const RecordingInfo& info, int indent) {
  nlohmann::json notes = nlohmann::json::array();
  for (const Annotation& a : info.annotations) notes.push_back({{"time_s", a.time_s}, {"text", a.text}, {"part", a.part}});
  const SessionDescription& d = info.description;
  return nlohmann::json{{"complete", info.complete},
                        {"duration_s", info.duration_s},
                        {"last_good_s", info.lastGood_s},
                        {"messages", info.messages},
                        {"bytes", info.bytes},
                        {"topics", info.topics},
                        {"parts", d.partNames()},
                        {"annotations", notes},
                        {"dropped_records", info.droppedKnown ? nlohmann::json(info.droppedRecords) : nlohmann::json()},
                        {"warnings", info.warnings},
                        {"document", d.document},
                        {"method", d.method},
                        {"device", d.device.name},
                        {"rate_hz", d.rate_hz},
                        {"software", d.software},
                        {"created_utc", d.created_utc}}
      // Topic names, annotations and warnings are the file's bytes, not always UTF-8: dump()
      // threw type_error.316 on them (fuzz_recording). A bad byte becomes U+FFFD instead.
      .dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace hg::session
