#include "hapticgrasp/geometry/isolated_load.hpp"

#include <Standard_Failure.hxx>

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <new>

#include "geometry/process_end.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/sanitized.hpp"

namespace hg::geometry {
namespace {

using Clock = std::chrono::steady_clock;

// The child's answer on the pipe: one tag, then the work's text or the error's message.
constexpr char kResult = 'R';
constexpr char kError = 'E';

std::string gibibytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g GiB", bytes / double(1ull << 30));
  return text;
}

void writeAll(int fd, const std::string& text) {
  for (std::size_t done = 0; done < text.size();) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the parent gave up reading
    done += n;
  }
}

std::string answerOf(const std::string& what, const std::function<std::string()>& work,
                     const IsolationLimits& limits) {
  try {
    return kResult + work();
  } catch (const std::bad_alloc&) {
    return kError + what + " needs more than " + gibibytes(limits.memoryBytes) +
           " of memory: given up";
  } catch (const std::exception& e) {
    return kError + std::string(e.what());
  } catch (const Standard_Failure& e) {
    return kError + what + ": OpenCASCADE failed: " + e.GetMessageString();
  }
}

// In the child: the limits, the work, its answer written to `fd`; never returns.
[[noreturn]] void runChild(int fd, const std::string& what,
                           const std::function<std::string()>& work,
                           const IsolationLimits& limits) {
  prctl(PR_SET_PDEATHSIG, SIGKILL);  // a parent that is killed leaves no loader running
  const rlimit memory{limits.memoryBytes, limits.memoryBytes};
#ifndef HG_SANITIZED  // ASan and TSan reserve terabytes of shadow address space: no limit holds
  setrlimit(RLIMIT_AS, &memory);
#else
  (void)memory;
#endif
  // OCCT prints its own traces (and "*** Abort ***" when a fault finds no handler): the
  // caller's error is one line, its own.
  if (const int null = open("/dev/null", O_WRONLY); null >= 0) {
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
  }
  writeAll(fd, answerOf(what, work, limits));
  _exit(0);  // no atexit handlers, no flushing of the parent's copied buffers
}

// Reads `fd` to its end into `out`; false if `deadline` came first.
bool readUntilEnd(int fd, Clock::time_point deadline, std::string& out) {
  char buffer[65536];
  for (;;) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int ready = poll(&p, 1, int(std::min<std::int64_t>(left.count(), 60'000)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) return false;
    if (ready == 0) continue;  // the deadline is checked above
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;
    out.append(buffer, n);
  }
}

}  // namespace

std::string isolatedLoad(const std::string& what, const std::function<std::string()>& work,
                         const IsolationLimits& limits) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw GeometryError(what + ": no pipe: " + std::strerror(errno));
  std::fflush(nullptr);  // what the parent buffered is not written a second time by the child
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    throw GeometryError(what + ": no child process: " + std::strerror(errno));
  }
  if (pid == 0) {
    close(fds[0]);
    runChild(fds[1], what, work, limits);
  }
  close(fds[1]);
  std::string answer;
  const Clock::time_point deadline =
      limits.time.count() > 0 ? Clock::now() + limits.time : Clock::time_point::max();
  const bool finished = readUntilEnd(fds[0], deadline, answer);
  close(fds[0]);
  if (!finished) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!finished)
    throw GeometryError(what + " did not finish within " + secondsText(limits.time) + ": given up");
  if (WIFSIGNALED(status))
    throw GeometryError(what + " crashed (" + signalName(WTERMSIG(status)) + ")");
  if (answer.empty() || (answer[0] != kResult && answer[0] != kError))
    throw GeometryError(what + " stopped without an answer (exit code " +
                        std::to_string(WEXITSTATUS(status)) + ")");
  if (answer[0] == kError) throw GeometryError(answer.substr(1));
  return answer.substr(1);
}

}  // namespace hg::geometry
