// recording.hpp: what a recording's readers report, as JSON.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/replay.hpp"

namespace hg::session {
namespace {

// A file's topic names, annotations and warnings are its bytes, not always UTF-8: the JSON
// once threw nlohmann's type_error.316 on them (fuzz_recording), ending `recording info
// --json`. A byte that is not UTF-8 is written as U+FFFD.
TEST(RecordingJson, BytesThatAreNotUtf8AreReplaced) {
  RecordingInfo info;
  info.topics["/tick\xff"] = 3;
  info.annotations.push_back({1.5, "grip \xc3", ""});
  info.warnings.push_back("chunk at 12: \xfe");
  const nlohmann::json j = nlohmann::json::parse(toJson(info));
  EXPECT_EQ(j["topics"]["/tick\xef\xbf\xbd"], 3);
  EXPECT_EQ(j["warnings"][0], "chunk at 12: \xef\xbf\xbd");
}

TEST(RecordingJson, ReplayWarningsThatAreNotUtf8AreReplaced) {
  ReplayCheck check;
  check.warnings.push_back("recorded by \xff");
  EXPECT_EQ(nlohmann::json::parse(toJson(check))["warnings"][0], "recorded by \xef\xbf\xbd");
}

}  // namespace
}  // namespace hg::session
