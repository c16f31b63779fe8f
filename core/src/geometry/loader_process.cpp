#include "hapticgrasp/geometry/loader_process.hpp"

#include <Standard_Failure.hxx>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <new>
#include <nlohmann/json.hpp>
#include <thread>

#include "geometry/process_end.hpp"
#include "geometry/u64_fields.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/display_shape.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/model_entry.hpp"
#include "hapticgrasp/geometry/occt_faults.hpp"
#include "hapticgrasp/sanitized.hpp"

extern char** environ;

namespace hg::geometry {
namespace {

using Clock = std::chrono::steady_clock;

constexpr char kRequest[4] = {'H', 'G', 'L', 'Q'};
constexpr char kAnswer[4] = {'H', 'G', 'L', 'A'};
constexpr std::uint64_t kMaxHeader = 1 << 20;
// An answer holds a part's entry: no larger than the helper's memory. A larger size is a
// helper gone wrong, refused before its bytes are read.
constexpr std::uint64_t kMaxBody = 8ull << 30;

}  // namespace

// A frame of the wire: its header, its body, its size in bytes.
struct LoaderProcess::Answer {
  nlohmann::json header;
  std::string body;
  std::size_t size = 0;
};

namespace {

using Frame = LoaderProcess::Answer;

std::string frameBytes(const char (&magic)[4], const nlohmann::json& header, std::string_view body) {
  const std::string head = header.dump();
  std::string bytes(magic, 4);
  putU64(bytes, head.size());
  bytes += head;
  putU64(bytes, body.size());
  bytes += body;
  return bytes;
}

enum class Parsed { Incomplete, Complete, Bad };

// One frame from the start of `bytes`, as far as they go; `why` says what is wrong with a bad one.
Parsed parseFrame(std::string_view bytes, const char (&magic)[4], Frame& out, std::string& why) {
  if (bytes.size() < 12) return Parsed::Incomplete;
  if (std::memcmp(bytes.data(), magic, 4) != 0) {
    why = "not a frame";
    return Parsed::Bad;
  }
  const std::uint64_t headerSize = getU64(bytes, 4);
  if (headerSize > kMaxHeader) {
    why = "a header of " + std::to_string(headerSize) + " bytes";
    return Parsed::Bad;
  }
  if (bytes.size() < 12 + headerSize + 8) return Parsed::Incomplete;
  const std::uint64_t bodySize = getU64(bytes, 12 + headerSize);
  if (bodySize > kMaxBody) {
    why = "a body of " + std::to_string(bodySize) + " bytes";
    return Parsed::Bad;
  }
  if (bytes.size() < 20 + headerSize + bodySize) return Parsed::Incomplete;
  out.header = nlohmann::json::parse(bytes.substr(12, headerSize), nullptr, false);
  if (out.header.is_discarded() || !out.header.is_object()) {
    why = "a header that is not a JSON object";
    return Parsed::Bad;
  }
  out.body.assign(bytes.substr(20 + headerSize, bodySize));
  out.size = 20 + headerSize + bodySize;
  return Parsed::Complete;
}

// --- the helper's side: blocking, one request at a time --------------------------------

bool writeAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    ssize_t n = send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n < 0 && errno == ENOTSOCK) n = write(fd, bytes.data(), bytes.size());  // a pipe: run by hand
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(n);
  }
  return true;
}

// A part: its model as the cache stores it, and the load's timing.
std::string loadedPart(const Frame& request, nlohmann::json& header) {
  const std::string name = request.header.at("name").get<std::string>();
  PartModel::LoadOptions options;
  options.checkSelfIntersection = request.header.at("check_self_intersection").get<bool>();
  options.parallel = request.header.at("parallel").get<bool>();
  const PartModelPtr part =
      PartModel::fromBrepText(request.body, parseLengthUnit(request.header.at("unit").get<std::string>()), name, options);
  // A defective part gets a robust back end, whose build meshes its damaged surfaces (where
  // fuzzing found BRepMesh's loops): rehearsed here first, so that a build that would not end
  // ends this process under its time limit, not a worker of FreeCAD's. Sound parts (exact)
  // are not rehearsed: their build costs FreeCAD's worker once only.
  if (part->backendChoice().backend != Backend::Exact) makePenetration(part);
  const PartLoadTiming& t = part->loadTiming();
  header = {{"done", true}, {"read_s", t.read_s}, {"check_s", t.check_s}, {"total_s", t.total_s}};
  return entryBytes(*part);
}

// A recorded shape to show: its checked text, once its display mesh has finished here.
std::string displayable(const Frame& request, nlohmann::json& header) {
  DisplayCheck check;
  check.mesh = true;
  std::string text = displayableBrepText(request.body, parseLengthUnit(request.header.at("unit").get<std::string>()),
                                         request.header.at("name").get<std::string>(), check);
  header = {{"done", true}};
  return text;
}

std::string answerTo(const Frame& request) {
  nlohmann::json header = {{"done", false}};
  std::string body;
  const std::string name = request.header.value("name", std::string("the part"));
  const unsigned long faultsBefore = occtFaultsCaught();
  try {
    const std::string job = request.header.at("job").get<std::string>();
    if (job == "part")
      body = loadedPart(request, header);
    else if (job == "display")
      body = displayable(request, header);
    else
      body = "a request the loader process does not know: " + job;
  } catch (const std::bad_alloc&) {
    body = "loading " + name + " needs more memory than the loader process may have: given up";
  } catch (const std::exception& e) {
    body = e.what();
  } catch (const Standard_Failure& e) {
    body = "loading " + name + ": OpenCASCADE failed: " + e.GetMessageString();
  }
  // A fault's jump lost what the frames it skipped held (memory, perhaps a lock): this
  // helper takes no further request (loader_process.hpp).
  if (occtFaultsCaught() != faultsBefore) header["retire"] = true;
  return frameBytes(kAnswer, header, body);
}

// --- the workbench's side: never blocks past the deadline --------------------------------

const char* unitText(LengthUnit unit) { return unit == LengthUnit::Metre ? "m" : "mm"; }

enum class Exchange { Answered, TimedOut, Cancelled, Closed, Garbled };

// Waits for `events` on `fd` until `deadline`, looking at `cancelled` every 50 ms:
// Answered when they came (or poll failed: the send or read that follows says what).
Exchange await(int fd, short events, Clock::time_point deadline, const std::atomic<bool>* cancelled) {
  for (;;) {
    if (cancelled && cancelled->load(std::memory_order_acquire)) return Exchange::Cancelled;
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return Exchange::TimedOut;
    pollfd p{fd, events, 0};
    const int ready = poll(&p, 1, int(std::min<std::int64_t>(left.count(), cancelled ? 50 : 60'000)));
    if (ready > 0) return Exchange::Answered;
    if (ready < 0 && errno != EINTR) return Exchange::Answered;
  }
}

// Sends `request` and reads one answer into `answer`, all before `deadline` and `cancelled`.
Exchange exchange(int fd, std::string_view request, Clock::time_point deadline, const std::atomic<bool>* cancelled,
                  Frame& answer, std::string& why) {
  while (!request.empty()) {
    if (const Exchange e = await(fd, POLLOUT, deadline, cancelled); e != Exchange::Answered) return e;
    const ssize_t n = send(fd, request.data(), request.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) return Exchange::Closed;
    request.remove_prefix(n);
  }
  std::string bytes;
  char buffer[1 << 16];
  for (;;) {
    switch (parseFrame(bytes, kAnswer, answer, why)) {
      case Parsed::Complete: return Exchange::Answered;
      case Parsed::Bad: return Exchange::Garbled;
      case Parsed::Incomplete: break;
    }
    if (const Exchange e = await(fd, POLLIN, deadline, cancelled); e != Exchange::Answered) return e;
    const ssize_t n = recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) return Exchange::Closed;
    bytes.append(buffer, n);
  }
}

// How a helper that stopped answering ended, once it has (at most 1 s): its exit status. A
// helper reaped here is gone (`reaped`): its pid may already be another process's.
std::string howItEnded(pid_t pid, bool& reaped) {
  int status = 0;
  reaped = false;
  for (int i = 0; i < 100; ++i) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) {
      reaped = true;
      if (WIFSIGNALED(status)) return "crashed (" + signalName(WTERMSIG(status)) + ")";
      return "stopped without an answer (exit code " + std::to_string(WEXITSTATUS(status)) + ")";
    }
    if (done < 0 && errno != EINTR) {  // reaped elsewhere (SIGCHLD ignored)
      reaped = true;
      return "stopped without an answer";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return "stopped answering";
}

}  // namespace

LoaderProcess::LoaderProcess(Options options) : options_(std::move(options)) {
  if (options_.command.empty() || options_.command.front().empty())
    throw std::invalid_argument("the loader process needs a program");
}

LoaderProcess::~LoaderProcess() {
  for (const Helper& helper : idle_) end(helper);
}

std::size_t LoaderProcess::started() const {
  std::lock_guard lock(mutex_);
  return started_;
}

std::vector<pid_t> LoaderProcess::idle() const {
  std::lock_guard lock(mutex_);
  std::vector<pid_t> pids;
  for (const Helper& h : idle_) pids.push_back(h.pid);
  return pids;
}

LoaderProcess::Helper LoaderProcess::start() {
  int sockets[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0)
    throw GeometryError(std::string("the loader process cannot start: no socket: ") + std::strerror(errno));
  // The helper reads and answers on its standard input; what OCCT prints goes nowhere.
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_adddup2(&files, sockets[1], STDIN_FILENO);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  // FreeCAD's threads block signals and Python ignores SIGPIPE: the helper starts clean.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  for (const int s : {SIGPIPE, SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGCHLD, SIGXCPU}) sigaddset(&defaults, s);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  std::vector<char*> argv;
  for (const std::string& a : options_.command) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int error = posix_spawnp(&pid, argv[0], &files, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attributes);
  close(sockets[1]);
  if (error != 0) {
    close(sockets[0]);
    throw GeometryError("the loader process cannot start (" + options_.command.front() + "): " + std::strerror(error));
  }
#ifndef HG_SANITIZED  // ASan and TSan reserve terabytes of shadow address space: no limit holds
  // Before the first request: the helper allocates next to nothing until it reads one.
  const rlimit memory{options_.limits.memoryBytes, options_.limits.memoryBytes};
  prlimit(pid, RLIMIT_AS, &memory, nullptr);
#endif
  std::lock_guard lock(mutex_);
  ++started_;
  return {pid, sockets[0]};
}

LoaderProcess::Helper LoaderProcess::take() {
  {
    std::lock_guard lock(mutex_);
    while (!idle_.empty()) {
      const Helper helper = idle_.back();
      idle_.pop_back();
      int status = 0;
      if (waitpid(helper.pid, &status, WNOHANG) == 0) return helper;  // alive
      close(helper.fd);  // died while idle (killed from outside): never handed a part
    }
  }
  return start();
}

void LoaderProcess::giveBack(Helper helper) {
  std::lock_guard lock(mutex_);
  idle_.push_back(helper);
}

void LoaderProcess::end(Helper helper) noexcept {
  kill(helper.pid, SIGKILL);
  close(helper.fd);
  int status = 0;
  while (waitpid(helper.pid, &status, 0) < 0 && errno == EINTR) {
  }
}

PartModelPtr LoaderProcess::load(std::string_view brep, LengthUnit unit, const std::string& name,
                                 const PartModel::LoadOptions& options, const std::atomic<bool>* cancelled) {
  const nlohmann::json header = {{"job", "part"},
                                 {"name", name},
                                 {"unit", unitText(unit)},
                                 {"check_self_intersection", options.checkSelfIntersection},
                                 {"parallel", options.parallel}};
  const std::string what = "loading " + name + " in the loader process";
  Frame answer = ask(frameBytes(kRequest, header, brep), what, cancelled);
  PartLoadTiming timing;
  timing.read_s = answer.header.value("read_s", 0.0);
  timing.check_s = answer.header.value("check_s", 0.0);
  timing.total_s = answer.header.value("total_s", 0.0);
  std::string why;
  PartModelPtr part = partFromEntry(answer.body, name, why, &timing);
  if (!part) throw GeometryError(what + ": its answer is unreadable (" + why + ")");
  return part;
}

std::string LoaderProcess::displayableText(std::string_view binaryBrep, LengthUnit unit, const std::string& name) {
  const nlohmann::json header = {{"job", "display"}, {"name", name}, {"unit", unitText(unit)}};
  return ask(frameBytes(kRequest, header, binaryBrep), "checking " + name + " for display in the loader process", nullptr)
      .body;
}

LoaderProcess::Answer LoaderProcess::ask(const std::string& request, const std::string& what,
                                         const std::atomic<bool>* cancelled) {
  Helper helper = take();
  const Clock::time_point deadline =
      options_.limits.time.count() > 0 ? Clock::now() + options_.limits.time : Clock::time_point::max();
  Answer answer;
  std::string why;
  switch (exchange(helper.fd, request, deadline, cancelled, answer, why)) {
    case Exchange::Answered: break;
    case Exchange::TimedOut:
      end(helper);
      throw GeometryError(what + " did not finish within " + secondsText(options_.limits.time) + ": given up");
    case Exchange::Cancelled:
      end(helper);
      throw GeometryError(what + " was stopped: the build was cancelled");
    case Exchange::Closed: {
      bool reaped = false;
      const std::string ended = howItEnded(helper.pid, reaped);
      if (reaped)
        close(helper.fd);
      else
        end(helper);
      throw GeometryError(what + " " + ended);
    }
    case Exchange::Garbled:
      end(helper);
      throw GeometryError(what + ": its answer is garbled (" + why + ")");
  }
  if (answer.header.value("retire", false))
    end(helper);
  else
    giveBack(helper);
  if (!answer.header.value("done", false)) throw GeometryError(answer.body);
  return answer;
}

int serveLoads(int fd) {
  std::string bytes;
  char buffer[1 << 16];
  for (;;) {
    Frame request;
    std::string why;
    Parsed parsed;
    while ((parsed = parseFrame(bytes, kRequest, request, why)) == Parsed::Incomplete) {
      const ssize_t n = read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        if (bytes.empty()) return 0;  // the workbench is done with this helper
        std::fprintf(stderr, "hapticgrasp-loader: the request stops after %zu bytes\n", bytes.size());
        return 2;
      }
      bytes.append(buffer, n);
    }
    if (parsed == Parsed::Bad) {
      std::fprintf(stderr, "hapticgrasp-loader: not a loader request (%s); the workbench starts this program\n",
                   why.c_str());
      return 2;
    }
    bytes.erase(0, request.size);
    if (!writeAll(fd, answerTo(request))) return 0;
  }
}

}  // namespace hg::geometry
