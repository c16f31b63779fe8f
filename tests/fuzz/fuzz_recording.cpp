// Session recordings (.mcap): what `recording info`, the report, `replay` and the Review
// panel read. readRecordingInfo (the reader, the session description, annotations),
// replay (the scene rebuilt from the attached binary BREPs, every tick re-simulated) and
// brepAsText (an attached shape checked, then handed to FreeCAD). Documented errors: McapError and
// SessionError; a truncated or damaged file otherwise reads with warnings.
#include "fuzz_support.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/session/mcap_reader.hpp"
#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/replay.hpp"

using namespace hg::session;

namespace {

void read(const std::string& path) {
  const RecordingInfo info = readRecordingInfo(path);
  toJson(info);
  for (const RecordedPart& part : info.description.parts)
    if (!part.brep.empty()) brepAsText(part);
  toJson(replay(path));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  hg::fuzz::quietOcct();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static hg::fuzz::InputFile file(".mcap");
  try {
    read(file.write(data, size));
  } catch (const McapError&) {
  } catch (const SessionError&) {
  }
  return 0;
}
