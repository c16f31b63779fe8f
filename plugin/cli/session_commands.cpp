#include "session_commands.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <iostream>
#include <string>
#include <vector>

#include "device_commands.hpp"
#include "hapticgrasp/geometry/isolated_load.hpp"
#include "hapticgrasp/geometry/occt_faults.hpp"
#include "hapticgrasp/install_layout.hpp"
#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/replay.hpp"

namespace hg::cli {

int record(servo::ServoBenchOptions options, bool json) { return benchServo(std::move(options), json); }

namespace {

// printf into a string: the verbs below compose their output in an isolated child.
template <class... Args>
void appendf(std::string& out, const char* format, Args... args) {
  const int n = std::snprintf(nullptr, 0, format, args...);
  const std::size_t at = out.size();
  out.resize(at + n + 1);
  std::snprintf(out.data() + at, n + 1, format, args...);
  out.resize(at + n);
}

std::string describeRecording(const std::string& path, bool json) {
  const session::RecordingInfo info = session::readRecordingInfo(path);
  if (json) return session::toJson(info) + "\n";
  std::string out;
  const session::SessionDescription& d = info.description;
  appendf(out, "recording %s: %s, %.3f s, %llu messages, %.2f MB\n", path.c_str(),
          info.complete ? "complete" : "cut short", info.duration_s, static_cast<unsigned long long>(info.messages),
          info.bytes / 1e6);
  appendf(out, "  recorded %s by %s (%s)\n", d.created_utc.c_str(), d.software.c_str(), d.build.c_str());
  appendf(out, "  %s method, %d fingertips, %.0f Hz, device '%s'%s%s\n", d.method.c_str(), d.fingertips, d.rate_hz,
          d.device.name.c_str(), d.document.empty() ? "" : ", document ", d.document.c_str());
  out += "  parts:";
  for (const session::RecordedPart& p : d.parts) appendf(out, " %s (%s)", p.name.c_str(), p.backend.c_str());
  out += "\n";
  for (const auto& [topic, count] : info.topics)
    appendf(out, "  %-28s %llu\n", topic.c_str(), static_cast<unsigned long long>(count));
  for (const session::Annotation& a : info.annotations)
    appendf(out, "  note at %.3f s%s%s: %s\n", a.time_s, a.part.empty() ? "" : " on ", a.part.c_str(), a.text.c_str());
  if (!info.complete) appendf(out, "  readable up to %.3f s\n", info.lastGood_s);
  for (const std::string& w : info.warnings) appendf(out, "  warning: %s\n", w.c_str());
  return out;
}

// The replay's output, after one character: '=' when bit-identical, '!' when not.
std::string replayRecording(const std::string& path, bool json) {
  const session::ReplayCheck c = session::replay(path);
  const bool identical = c.stateMismatches == 0 && c.eventMismatches == 0 && c.maxForceDiff_N == 0 && c.maxPoseDiff_m == 0;
  std::string out(1, identical ? '=' : '!');
  if (json) return out + session::toJson(c) + "\n";
  appendf(out, "replay %s: %llu ticks re-simulated; %s\n", path.c_str(), static_cast<unsigned long long>(c.ticks),
          identical ? "bit-identical to the recording" : "differs from the recording");
  appendf(out, "  state mismatches %llu, event mismatches %llu, largest force difference %.3g N, "
          "largest pose difference %.3g m\n",
          static_cast<unsigned long long>(c.stateMismatches), static_cast<unsigned long long>(c.eventMismatches),
          c.maxForceDiff_N, c.maxPoseDiff_m);
  if (c.firstMismatchTick)
    appendf(out, "  first difference at tick %llu\n", static_cast<unsigned long long>(c.firstMismatchTick));
  for (const std::string& w : c.warnings) appendf(out, "  warning: %s\n", w.c_str());
  return out;
}

// A recording is someone else's file, and its attachments are B-reps that OCCT reads: as
// `parts info` does with a part, the work runs in a child under a time and memory limit
// (isolated_load.hpp), with OCCT's fault handlers, so a hostile file gives one error line.
std::string isolated(const std::string& path, const std::string& what, double timeLimit_s,
                     const std::function<std::string()>& work) {
  geometry::IsolationLimits limits;
  limits.time = std::chrono::milliseconds(std::llround(timeLimit_s * 1e3));
  return geometry::isolatedLoad(what, [&] {
    geometry::catchOcctFaults();
    try {
      return work();
    } catch (const std::exception& e) {  // "part 'loft': its attached BREP does not read": in which file?
      const std::string message = e.what();
      throw std::runtime_error(message.find(path) == std::string::npos ? path + ": " + message : message);
    }
  }, limits);
}

}  // namespace

int recordingInfo(const std::string& path, bool json, double timeLimit_s) {
  std::fputs(isolated(path, path + ": reading the recording", timeLimit_s, [&] { return describeRecording(path, json); }).c_str(),
             stdout);
  return 0;
}

int replay(const std::string& path, bool check, bool json, double timeLimit_s) {
  const std::string out = isolated(path, path + ": replaying", timeLimit_s, [&] { return replayRecording(path, json); });
  std::fputs(out.c_str() + 1, stdout);
  return check && out.front() != '=' ? 1 : 0;
}

// The report is drawn by Python's matplotlib (Debian's) from what the core's reader gives
// through the _hapticgrasp module: the workbench's freecad.hapticgrasp.report, run as a module
// so that it imports the compiled core as the workbench does. In the build tree the addon folder
// holds both; installed, the Python files are in FreeCAD's Mod folder and the compiled module in
// the prefix's dist-packages, which the package's __init__ joins (pkgutil.extend_path).
struct ReportRun {
  std::vector<std::string> argv;  // before the recording's path
  std::string pythonPath;         // empty: leave PYTHONPATH as it is
};

ReportRun reportRun() {
  if (const char* script = std::getenv("HAPTICGRASP_REPORT_SCRIPT"); script && *script)
    return {{HG_PYTHON, script}, ""};
  std::filesystem::path addon = HG_FREECAD_ADDON_DIR;
  std::string pythonPath = addon.string();
  if (const auto prefix = hg::installPrefix()) {
    addon = *prefix / "share" / "freecad" / "Mod" / "HapticGrasp";
    pythonPath = addon.string() + ":" + (*prefix / "lib" / "python3" / "dist-packages").string();
  }
  if (!std::filesystem::exists(addon / "freecad" / "hapticgrasp" / "report.py"))
    throw std::runtime_error("report: the workbench's report.py is not in " + addon.string() +
                             " (build the _hapticgrasp module, install the package, or set HAPTICGRASP_REPORT_SCRIPT)");
  if (const char* inherited = std::getenv("PYTHONPATH"); inherited && *inherited) pythonPath += std::string(":") + inherited;
  return {{HG_PYTHON, "-m", "freecad.hapticgrasp.report"}, pythonPath};
}

int report(const std::string& path, const std::string& output) {
  ReportRun run = reportRun();
  std::filesystem::path out = output;
  // argv and the environment are built before fork: the child only execs.
  std::vector<std::string> args = run.argv;
  args.insert(args.end(), {path, "-o", out.string()});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e)
    if (run.pythonPath.empty() || std::strncmp(*e, "PYTHONPATH=", 11) != 0) env.emplace_back(*e);
  if (!run.pythonPath.empty()) env.push_back("PYTHONPATH=" + run.pythonPath);
  std::vector<char*> envp;
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error(std::string("report: cannot start python3: ") + std::strerror(errno));
  if (child == 0) {
    // The Python the _hapticgrasp module was built for (Debian's, with its matplotlib).
    execve(HG_PYTHON, argv.data(), envp.data());
    std::fprintf(stderr, "hapticgrasp: report: cannot run " HG_PYTHON ": %s\n", std::strerror(errno));
    _exit(127);
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return 2;
  std::printf("report: %s\n", out.c_str());
  return 0;
}

}  // namespace hg::cli
