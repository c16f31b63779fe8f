#include "doctor.hpp"

#include <glob.h>
#include <spawn.h>
#include <sys/wait.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "hapticgrasp/device/udev_rule.hpp"
#include "hapticgrasp/servo/realtime_access.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"

namespace hg::cli {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// The udev rule the package installs (packaging/): uaccess for the supported devices.
constexpr const char* kUdevRule = device::kUdevRuleFile;

// Runs argv (looked up in PATH) with no shell between, and returns what it printed on
// stdout and stderr: a FreeCAD found in an odd PATH folder is a path, never shell words.
std::string runCapturing(std::vector<std::string> argv) {
  int out[2];
  if (pipe(out) != 0) return "";
  std::vector<char*> args;
  for (std::string& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, out[0]);
  pid_t child = -1;
  const int spawned = posix_spawnp(&child, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(out[1]);
  std::string output;
  if (spawned == 0) {
    char buffer[4096];
    for (ssize_t n; (n = read(out[0], buffer, sizeof buffer)) != 0;) {
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) break;
      output.append(buffer, static_cast<std::size_t>(n));
    }
    int status = 0;
    while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
  }
  close(out[0]);
  return output;
}

std::vector<std::string> globPaths(const std::string& pattern) {
  std::vector<std::string> out;
  glob_t g{};
  if (glob(pattern.c_str(), 0, nullptr, &g) == 0)
    for (std::size_t i = 0; i < g.gl_pathc; ++i) out.emplace_back(g.gl_pathv[i]);
  globfree(&g);
  return out;
}

std::string firstExisting(const std::vector<std::string>& paths) {
  std::error_code ec;
  for (const std::string& p : paths)
    if (fs::exists(p, ec)) return p;
  return "";
}

std::string findInPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = dirs.find(':', start);
    const std::string dir = dirs.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return "";
}

json realtime() {
  const servo::RealtimeAccess a = servo::probeRealtime(servo::ServoConfig{}.fifoPriority);
  return {{"granted", a.granted}, {"priority", a.priority}, {"rtprio_limit", a.rtprioLimit},
          {"cap_sys_nice", a.capSysNice}, {"why", a.why}, {"fix", a.fix}};
}

json memoryLock() {
  const servo::MemoryLockAccess m = servo::probeMemoryLock();
  return {{"granted", m.granted}, {"limit_bytes", m.limitBytes}, {"why", m.why}, {"fix", m.fix}};
}

json hidraw() {
  const std::vector<std::string> nodes = globPaths("/dev/hidraw*");
  std::vector<std::string> denied;
  for (const std::string& n : nodes)
    if (access(n.c_str(), R_OK | W_OK) != 0) denied.push_back(n);
  const std::string rule = firstExisting({std::string("/etc/udev/rules.d/") + kUdevRule,
                                          std::string("/usr/lib/udev/rules.d/") + kUdevRule,
                                          std::string("/lib/udev/rules.d/") + kUdevRule});
  json j{{"devices", nodes.size()}, {"accessible", nodes.size() - denied.size()}, {"denied", denied},
         {"udev_rule", rule.empty() ? json(nullptr) : json(rule)}};
  j["ok"] = denied.empty();
  if (nodes.empty())
    j["why"] = "no HID device attached (hidraw)";
  else
    j["why"] = std::to_string(nodes.size() - denied.size()) + " of " + std::to_string(nodes.size()) +
               " hidraw devices readable and writable";
  j["fix"] = denied.empty() ? ""
                            : std::string(rule.empty() ? "install the package's udev rule (" + std::string(kUdevRule) +
                                                             ": access for the logged-in user), then replug the device"
                                                       : "replug the device (the udev rule " + rule +
                                                             " grants the logged-in user access on plugging)");
  return j;
}

// Runs `freecadcmd` on a script written to a private temporary file: FreeCAD's version and
// whether its Python imports the workbench's compiled module (either layout).
json freecadAndAddon() {
  json fc{{"found", false}}, addon{{"installed", false}, {"imports", false}};
  const std::string cmd = findInPath("freecadcmd");
  const char* home = std::getenv("HOME");
  const std::string mod = firstExisting({std::string(home ? home : "/nonexistent") + "/.local/share/FreeCAD/Mod/HapticGrasp",
                                         "/usr/share/freecad/Mod/HapticGrasp", "/usr/lib/freecad/Mod/HapticGrasp"});
  if (!mod.empty()) {
    std::error_code ec;
    addon["installed"] = true;
    addon["path"] = mod;
    addon["resolved"] = fs::weakly_canonical(mod, ec).string();
  }
  if (cmd.empty()) {
    fc["why"] = "freecadcmd not found in PATH";
    fc["fix"] = "install FreeCAD (sudo apt install freecad)";
    addon["why"] = "FreeCAD not found";
    addon["fix"] = fc["fix"];
    return {{"freecad", fc}, {"addon", addon}};
  }
  fc["found"] = true;
  fc["path"] = cmd;
  const char* tmp = std::getenv("TMPDIR");
  std::string scriptName = std::string(tmp && *tmp ? tmp : "/tmp") + "/hapticgrasp-doctor-XXXXXX.py";
  char* scriptPath = scriptName.data();
  const int fd = mkstemps(scriptPath, 3);  // 0600, a fresh name: nobody else's file is run
  if (fd < 0) {
    fc["why"] = "cannot create a temporary file to ask FreeCAD";
    return {{"freecad", fc}, {"addon", addon}};
  }
  const std::string script =
      "import FreeCAD\n"
      "print('HG_VERSION ' + '.'.join(FreeCAD.Version()[:3]))\n"
      "try:\n"
      "    try:\n"
      "        from freecad.hapticgrasp import _hapticgrasp as m\n"
      "    except ImportError:\n"
      "        import _hapticgrasp as m\n"
      "    print('HG_IMPORT_OK ' + m.__file__)\n"
      "except Exception as e:\n"
      "    print('HG_IMPORT_FAIL ' + str(e).replace('\\n', ' '))\n";
  const bool written = write(fd, script.data(), script.size()) == static_cast<ssize_t>(script.size());
  close(fd);
  const std::string output = written ? runCapturing({"timeout", "120", cmd, scriptPath}) : "";
  unlink(scriptPath);
  const auto field = [&](const std::string& key) -> std::string {
    const std::size_t at = output.find(key + " ");
    if (at == std::string::npos) return "";
    const std::size_t from = at + key.size() + 1;
    return output.substr(from, output.find('\n', from) - from);
  };
  fc["version"] = field("HG_VERSION");
  fc["why"] = fc["version"] == "" ? "freecadcmd did not report its version" : "FreeCAD " + fc["version"].get<std::string>();
  const std::string ok = field("HG_IMPORT_OK"), fail = field("HG_IMPORT_FAIL");
  addon["imports"] = !ok.empty();
  if (!ok.empty()) {
    addon["module"] = ok;
    addon["why"] = "FreeCAD's Python imports " + ok;
    addon["fix"] = "";
  } else {
    addon["why"] = mod.empty() ? "the workbench is not installed in a FreeCAD Mod folder"
                               : "FreeCAD's Python cannot import the module: " + (fail.empty() ? output : fail);
    addon["fix"] = mod.empty() ? "install the package, or link build/freecad/HapticGrasp into ~/.local/share/FreeCAD/Mod"
                               : "rebuild the workbench against this FreeCAD's Python (3.11) and reinstall it";
  }
  return {{"freecad", fc}, {"addon", addon}};
}

json audio() {
  const char* pulse = std::getenv("PULSE_SERVER");
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  const std::string runtimeDir = runtime ? runtime : "/run/user/" + std::to_string(getuid());
  std::string how;
  std::error_code ec;
  if (pulse && *pulse)
    how = std::string("PULSE_SERVER=") + pulse;
  else if (fs::exists(runtimeDir + "/pulse/native", ec))
    how = "a PulseAudio/PipeWire server (" + runtimeDir + "/pulse/native)";
  else if (!globPaths("/dev/snd/pcmC*D*p").empty())
    how = "ALSA playback devices (/dev/snd)";
  json j{{"available", !how.empty()}};
  j["why"] = how.empty() ? "no sound server and no ALSA playback device: the grasp cues stay silent" : how;
  j["fix"] = how.empty() ? "run the desktop's sound server (PipeWire or PulseAudio), or connect an audio output" : "";
  return j;
}

void addProblem(json& problems, const std::string& area, const json& finding, const char* okKey) {
  if (finding.value(okKey, false)) return;
  problems.push_back(area + ": " + finding.value("why", "") +
                     (finding.value("fix", "").empty() ? "" : " -- fix: " + finding.value("fix", "")));
}

}  // namespace

json doctorFindings() {
  json j;
  j["realtime"] = realtime();
  j["memory_lock"] = memoryLock();
  j["hidraw"] = hidraw();
  const json fc = freecadAndAddon();
  j["freecad"] = fc["freecad"];
  j["addon"] = fc["addon"];
  j["audio"] = audio();
  json problems = json::array();
  addProblem(problems, "real time", j["realtime"], "granted");
  addProblem(problems, "memory lock", j["memory_lock"], "granted");
  addProblem(problems, "HID devices", j["hidraw"], "ok");
  addProblem(problems, "FreeCAD", j["freecad"], "found");
  if (j["freecad"].value("found", false)) addProblem(problems, "workbench", j["addon"], "imports");
  addProblem(problems, "audio", j["audio"], "available");
  j["problems"] = problems;
  return j;
}

int doctor(bool asJson) {
  const json j = doctorFindings();
  if (asJson) {
    std::cout << j.dump(2) << std::endl;
    return 0;
  }
  const auto line = [](const char* area, const json& f, const char* okKey) {
    const bool ok = f.value(okKey, false);
    std::cout << area << (ok ? "  ok       " : "  PROBLEM  ") << f.value("why", "") << "\n";
    if (!ok && !f.value("fix", "").empty()) std::cout << "                        fix: " << f.value("fix", "") << "\n";
  };
  line("real time   ", j["realtime"], "granted");
  line("memory lock ", j["memory_lock"], "granted");
  line("HID devices ", j["hidraw"], "ok");
  line("FreeCAD     ", j["freecad"], "found");
  line("workbench   ", j["addon"], "imports");
  line("audio       ", j["audio"], "available");
  std::cout << j["problems"].size() << " problem(s)" << std::endl;
  return 0;
}

}  // namespace hg::cli
