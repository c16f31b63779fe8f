#pragma once
// Parts loaded in a helper process, for a process that cannot fork: FreeCAD runs threads,
// and fork() copies only the calling one (isolated_load.hpp is the command line's way). A
// shape that crashes OCCT, sends one of its algorithms into a loop or eats memory then costs
// the helper, not FreeCAD and the user's unsaved work: the load becomes one GeometryError
// naming what happened, and the next load starts a fresh helper.
//
// The helper (`hapticgrasp-loader`: plugin/loader; install_layout.hpp: loaderProgram) loads
// one part after another: starting a process costs about 0.1 s, which a scene of 2,780
// distinct shapes cannot pay for each. Idle helpers wait in a pool; a load takes one or
// starts one, so a scene's workers load side by side. A helper inherits the scheduling and
// CPUs of the thread that starts it (a scene's workers: SCHED_BATCH, nice 19, off the servo's
// CPU), gets the memory limit as its address space, and exits when its parent goes. A
// helper in which OCCT faulted during a load (occt_faults.hpp: occtFaultsCaught) says so in
// its answer and is ended, not pooled: the fault's jump skipped destructors, losing tens of
// kB a part (and whatever lock a skipped frame held), which a helper loading one damaged
// part after another would pile up.
//
// The wire, one Unix socket both ways: a frame is a 4-byte magic, a JSON header and a body,
// each after its size (u64). A request's header names the part, its unit and load options,
// its body is the BREP text; the answer's header says whether the part loaded and how long
// that took, its body is the model as the cache stores it (model_entry.hpp) or the error. A
// recorded shape to show (display_shape.hpp) goes the same way, answered with its text.
// Hand-written: no Debian library runs a function in a pooled child process.
#include <sys/types.h>

#include <atomic>
#include <cstddef>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/geometry/isolated_load.hpp"
#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::geometry {

class LoaderProcess {
 public:
  struct Options {
    std::vector<std::string> command;  // the helper and its arguments (loaderProgram())
    // Per part. A real part no one here made takes up to a few seconds to check; the
    // workbench waits longer than the command line's 8 s, since refusing a valid part for
    // being slow on a busy machine is worse than waiting for it.
    IsolationLimits limits{std::chrono::seconds(60), 8ull << 30};
  };

  explicit LoaderProcess(Options options);
  ~LoaderProcess();  // ends the idle helpers
  LoaderProcess(const LoaderProcess&) = delete;
  LoaderProcess& operator=(const LoaderProcess&) = delete;

  // PartModel::fromBrepText(brep, unit, name, options), computed by a helper; safe from any
  // thread. A defective part's robust back end is built there once too (and dropped), so
  // that the caller's own build of it is known to end. Once `cancelled` is set (a build
  // cancelled, FreeCAD closing), the load ends within 50 ms, its helper killed. Throws GeometryError: the load's own error, or how the helper ended (crashed,
  // out of time, unable to start, an unreadable answer), naming the part.
  PartModelPtr load(std::string_view brep, LengthUnit unit, const std::string& name,
                    const PartModel::LoadOptions& options = {}, const std::atomic<bool>* cancelled = nullptr);
  // displayableBrepText(binaryBrep, unit, name) with its display mesh, computed by a helper
  // (display_shape.hpp): a recorded shape for the Review panel. Throws GeometryError: the
  // check's own ("is refused: ..."), or how the helper ended.
  std::string displayableText(std::string_view binaryBrep, LengthUnit unit, const std::string& name);

  struct Answer;  // a frame of the wire (loader_process.cpp)

  const Options& options() const { return options_; }
  std::size_t started() const;  // helpers started so far
  std::vector<pid_t> idle() const;  // the helpers waiting for a part

 private:
  struct Helper {
    pid_t pid = -1;
    int fd = -1;
  };
  // Sends `request` to a helper and returns its answer; throws GeometryError naming `what`.
  Answer ask(const std::string& request, const std::string& what, const std::atomic<bool>* cancelled);
  Helper take();
  Helper start();
  void giveBack(Helper helper);
  static void end(Helper helper) noexcept;  // kills and reaps

  Options options_;
  mutable std::mutex mutex_;
  std::vector<Helper> idle_;
  std::size_t started_ = 0;
};

// The helper's side: answers the requests on `fd` (a socket or any stream) one after another
// until it closes. Returns 0 at its end, 2 for a frame that is not a request (said on stderr).
int serveLoads(int fd);

}  // namespace hg::geometry
