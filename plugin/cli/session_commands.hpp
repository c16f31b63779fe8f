#pragma once
// The session verbs of the hapticgrasp command: record, recording info, replay, report.
#include <string>

#include "hapticgrasp/servo/servo_bench.hpp"

namespace hg::cli {

// hapticgrasp record: the real servo thread (as `bench servo`), recorded to options.recordPath.
int record(servo::ServoBenchOptions options, bool json);
// hapticgrasp recording info FILE: what a recording holds; works on truncated files.
// Both read in a child process given up after timeLimit_s (0: never): recordings are
// untrusted input. Throw GeometryError with one line when the child fails.
int recordingInfo(const std::string& path, bool json, double timeLimit_s);
// hapticgrasp replay FILE [--check]: re-simulates; with --check exits 1 unless bit-identical.
int replay(const std::string& path, bool check, bool json, double timeLimit_s);
// hapticgrasp report FILE -o REPORT.html: the session's report (Python + matplotlib).
int report(const std::string& path, const std::string& output);

}  // namespace hg::cli
