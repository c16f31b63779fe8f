#pragma once
// A recording as its readers see it (`hapticgrasp recording info`, the report, the Review
// panel): the session's description, what the file holds per topic, how long it runs, the
// reviewers' annotations, and whether it was closed properly or cut short (a killed
// recorder, a full disk) and how much of it could be read.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "hapticgrasp/session/session_description.hpp"

namespace hg::session {

class McapReader;

inline constexpr std::string_view kRecordingMetadata = "hapticgrasp.recording";  // written at the end

struct Annotation {
  double time_s = 0;  // session time (from the first message)
  std::string text;
  std::string part;   // under the hand, "" if none
};

struct RecordingInfo {
  bool complete = false;       // closed properly
  double duration_s = 0;       // first to last message read
  double lastGood_s = 0;       // the last moment read before anything was lost
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;
  std::map<std::string, std::uint64_t> topics;  // messages per topic
  std::uint64_t droppedRecords = 0;             // ticks the recorder lost (its ring was full)
  bool droppedKnown = false;                    // false: the file ends before the recorder said
  std::string recorderError;                    // why recording stopped early, if it did
  std::vector<Annotation> annotations;
  std::vector<std::string> warnings;
  SessionDescription description;
  std::uint64_t firstTime_ns = 0;
};

// The session's description from a reader that has read the file's first records, with
// each part's BREP taken from its attachment (withShapes; the reader must then have read
// attachment data). Throws SessionError if there is none, or a part's BREP is missing.
SessionDescription readDescription(const McapReader& reader, bool withShapes = true);

// Reads the whole file (streaming). Throws McapError for a file that is not MCAP, and
// SessionError for one without a session; a truncated file reads with complete == false.
RecordingInfo readRecordingInfo(const std::string& path);

// {"complete", "duration_s", "last_good_s", "messages", "bytes", "topics": {name: count},
//  "parts": [...], "annotations": [{"time_s", "text", "part"}], "dropped_records",
//  "warnings": [...], "document", "method", "device", "rate_hz", "software", "created_utc"}
std::string toJson(const RecordingInfo& info, int indent = 2);

}  // namespace hg::session
