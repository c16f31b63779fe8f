#include "session_commands.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "device_commands.hpp"
#include "hapticgrasp/install_layout.hpp"
#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/replay.hpp"

namespace hg::cli {

int record(servo::ServoBenchOptions options, bool json) { return benchServo(std::move(options), json); }

int recordingInfo(const std::string& path, bool json) {
  const session::RecordingInfo info = session::readRecordingInfo(path);
  if (json) {
    std::cout << session::toJson(info) << std::endl;
    return 0;
  }
  const session::SessionDescription& d = info.description;
  std::printf("recording %s: %s, %.3f s, %llu messages, %.2f MB\n", path.c_str(),
              info.complete ? "complete" : "cut short", info.duration_s,
              static_cast<unsigned long long>(info.messages), info.bytes / 1e6);
  std::printf("  recorded %s by %s (%s)\n", d.created_utc.c_str(), d.software.c_str(), d.build.c_str());
  std::printf("  %s method, %d fingertips, %.0f Hz, device '%s'%s%s\n", d.method.c_str(), d.fingertips, d.rate_hz,
              d.device.name.c_str(), d.document.empty() ? "" : ", document ", d.document.c_str());
  std::printf("  parts:");
  for (const session::RecordedPart& p : d.parts) std::printf(" %s (%s)", p.name.c_str(), p.backend.c_str());
  std::printf("\n");
  for (const auto& [topic, count] : info.topics)
    std::printf("  %-28s %llu\n", topic.c_str(), static_cast<unsigned long long>(count));
  for (const session::Annotation& a : info.annotations)
    std::printf("  note at %.3f s%s%s: %s\n", a.time_s, a.part.empty() ? "" : " on ", a.part.c_str(), a.text.c_str());
  if (!info.complete) std::printf("  readable up to %.3f s\n", info.lastGood_s);
  for (const std::string& w : info.warnings) std::printf("  warning: %s\n", w.c_str());
  return 0;
}

int replay(const std::string& path, bool check, bool json) {
  const session::ReplayCheck c = session::replay(path);
  const bool identical = c.stateMismatches == 0 && c.eventMismatches == 0 && c.maxForceDiff_N == 0 && c.maxPoseDiff_m == 0;
  if (json) {
    std::cout << session::toJson(c) << std::endl;
  } else {
    std::printf("replay %s: %llu ticks re-simulated; %s\n", path.c_str(), static_cast<unsigned long long>(c.ticks),
                identical ? "bit-identical to the recording" : "differs from the recording");
    std::printf("  state mismatches %llu, event mismatches %llu, largest force difference %.3g N, "
                "largest pose difference %.3g m\n",
                static_cast<unsigned long long>(c.stateMismatches), static_cast<unsigned long long>(c.eventMismatches),
                c.maxForceDiff_N, c.maxPoseDiff_m);
    if (c.firstMismatchTick) std::printf("  first difference at tick %llu\n", static_cast<unsigned long long>(c.firstMismatchTick));
    for (const std::string& w : c.warnings) std::printf("  warning: %s\n", w.c_str());
  }
  return check && !identical ? 1 : 0;
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
