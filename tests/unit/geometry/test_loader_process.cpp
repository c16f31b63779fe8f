// Parts loaded in the workbench's loader process: the same part as a load in this process,
// the load's own errors as their messages, and a helper that crashes, hangs, answers garbage
// or cannot start as one GeometryError naming the part, after which the next load works.
#include "hapticgrasp/geometry/loader_process.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <thread>

#include <BinTools.hxx>

#include "geometry/part_answers.hpp"
#include "hapticgrasp/geometry/display_shape.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/install_layout.hpp"
#include "test_shapes.hpp"

namespace hg::geometry {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using namespace std::chrono_literals;

LoaderProcess::Options realHelper(std::chrono::milliseconds time = 60s) {
  LoaderProcess::Options o;
  o.command = {HG_LOADER_PROGRAM};
  o.limits.time = time;
  return o;
}

// Under ThreadSanitizer, the helpers this process starts report no signal-unsafe calls. OCCT
// leaves its fault handler by __longjmp_chk (Debian builds it with _FORTIFY_SOURCE), which
// TSan does not intercept, so TSan believes the helper never left the handler and reports each
// later allocation in it. Helpers inherit this process's environment. Elsewhere a no-op.
class HelpersIgnoreSignalSafetyUnderTsan {
 public:
  HelpersIgnoreSignalSafetyUnderTsan() {
#if defined(__SANITIZE_THREAD__)
    const char* options = std::getenv("TSAN_OPTIONS");
    saved_ = options ? std::optional<std::string>(options) : std::nullopt;
    setenv("TSAN_OPTIONS", (saved_.value_or("") + ":report_signal_unsafe=0").c_str(), 1);
#endif
  }
  ~HelpersIgnoreSignalSafetyUnderTsan() {
#if defined(__SANITIZE_THREAD__)
    if (saved_) setenv("TSAN_OPTIONS", saved_->c_str(), 1);
    else unsetenv("TSAN_OPTIONS");
#endif
  }
  HelpersIgnoreSignalSafetyUnderTsan(const HelpersIgnoreSignalSafetyUnderTsan&) = delete;
  HelpersIgnoreSignalSafetyUnderTsan& operator=(const HelpersIgnoreSignalSafetyUnderTsan&) = delete;

 private:
  std::optional<std::string> saved_;
};

// A stand-in helper: a shell script, for ends the real one cannot be made to meet on demand.
LoaderProcess::Options shellHelper(const std::string& script, std::chrono::milliseconds time = 10s) {
  LoaderProcess::Options o;
  o.command = {"/bin/sh", "-c", script};
  o.limits.time = time;
  return o;
}

std::string errorOf(LoaderProcess& loader, const std::string& brep, const std::string& name = "Bracket") {
  try {
    loader.load(brep, LengthUnit::Millimetre, name);
  } catch (const GeometryError& e) {
    return e.what();
  }
  ADD_FAILURE() << "the load answered; expected a GeometryError";
  return "";
}

// A helper's state letter from /proc (Z: a zombie), or 0 once it is gone.
char processState(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');
  return close == std::string::npos || close + 2 >= text.size() ? 0 : text[close + 2];
}

// Waits (at most 10 s) until the helper runs: it has been handed a part and is loading it.
void awaitLoading(pid_t helper) {
  const auto start = std::chrono::steady_clock::now();
  while (processState(helper) != 'R' && std::chrono::steady_clock::now() - start < 10s)
    std::this_thread::sleep_for(1ms);
}

TEST(LoaderProcess, TheBuildTreesProgramIsTheOneTheWorkbenchFinds) {
  unsetenv("HAPTICGRASP_LOADER");
  EXPECT_EQ(std::filesystem::canonical(loaderProgram()), std::filesystem::canonical(HG_LOADER_PROGRAM));
}

TEST(LoaderProcess, APartLoadsAsItDoesInThisProcess) {
  LoaderProcess loader(realHelper());
  for (const std::string name : {"block", "cylinder", "loft"}) {
    const PartModelPtr here = PartModel::fromBrepText(test::sample(name), LengthUnit::Millimetre, name);
    const PartModelPtr there = loader.load(test::sample(name), LengthUnit::Millimetre, name);
    EXPECT_EQ(there->name(), name);
    test::expectSameAnswers(here, there);
    EXPECT_GT(there->loadTiming().check_s, 0.0) << "the helper's own check time";
  }
  const PartModelPtr defect = loader.load(test::corpus("defect_crossing_faces"), LengthUnit::Millimetre, "d");
  test::expectSameAnswers(PartModel::fromBrepText(test::corpus("defect_crossing_faces"), LengthUnit::Millimetre, "d"),
                          defect);
  EXPECT_EQ(loader.started(), 1u) << "one helper, one part after another";
  EXPECT_EQ(loader.idle().size(), 1u);
}

TEST(LoaderProcess, TheUnitAndOptionsReachTheHelper) {
  LoaderProcess loader(realHelper());
  PartModel::LoadOptions noCrossings;
  noCrossings.checkSelfIntersection = false;
  const PartModelPtr metres = loader.load(test::sample("cylinder"), LengthUnit::Metre, "m", noCrossings);
  const PartModelPtr here = PartModel::fromBrepText(test::sample("cylinder"), LengthUnit::Metre, "m", noCrossings);
  EXPECT_EQ(metres->metresPerUnit(), 1.0);
  test::expectSameAnswers(here, metres);
}

TEST(LoaderProcess, TheLoadsOwnErrorIsItsMessage) {
  LoaderProcess loader(realHelper());
  std::string here;
  try {
    PartModel::fromBrepText("not a shape", LengthUnit::Millimetre, "Bracket");
  } catch (const GeometryError& e) {
    here = e.what();
  }
  ASSERT_FALSE(here.empty());
  EXPECT_EQ(errorOf(loader, "not a shape"), here);
  EXPECT_EQ(loader.idle().size(), 1u) << "a refused part costs no helper";
  EXPECT_EQ(loader.load(test::sample("block"), LengthUnit::Millimetre, "b")->faces().Extent(), 58);
  EXPECT_EQ(loader.started(), 1u);
}

// A part whose check faults inside OCCT (a fuzz_brep input): refused with the error the
// helper's handlers made of the fault, and that helper is ended, not pooled, since the
// fault's jump lost what the frames it skipped held. A sound part's helper is kept.
TEST(LoaderProcess, AHelperInWhichOcctFaultedIsEndedNotPooled) {
  std::ifstream in(std::string(HG_TEST_DATA_DIR) + "/../fuzz/corpus/brep/leak_fault_in_checks.brep");
  const std::string faulting((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(faulting.empty());
  const HelpersIgnoreSignalSafetyUnderTsan tsan;
  LoaderProcess loader(realHelper());
  loader.load(test::sample("block"), LengthUnit::Millimetre, "b");
  ASSERT_EQ(loader.idle().size(), 1u);
  const pid_t helper = loader.idle().at(0);
  EXPECT_THAT(errorOf(loader, faulting, "Damaged"), HasSubstr("SIGSEGV"));
  EXPECT_TRUE(loader.idle().empty());
  EXPECT_EQ(processState(helper), 0) << "ended and reaped";
  EXPECT_EQ(loader.load(test::sample("block"), LengthUnit::Millimetre, "b")->faces().Extent(), 58);
  EXPECT_EQ(loader.started(), 2u);
  EXPECT_EQ(loader.idle().size(), 1u);
}

// The real helper, killed and stopped mid-load from outside: the load says so, and the next
// load gets a new helper. (Killed, not sent SIGSEGV: the helper's OCCT handlers would turn
// that into an error inside the readers, as they do a fault of OCCT's own.)
TEST(LoaderProcess, AHelperKilledMidLoadIsNamedAndReplaced) {
  LoaderProcess loader(realHelper());
  loader.load(test::sample("cylinder"), LengthUnit::Millimetre, "c");
  const pid_t helper = loader.idle().at(0);
  std::thread crash([helper] {
    awaitLoading(helper);
    kill(helper, SIGKILL);
  });
  const std::string error = errorOf(loader, test::corpus("machined_plate"), "Plate");
  crash.join();
  EXPECT_EQ(error, "loading Plate in the loader process crashed (SIGKILL, Killed)");
  EXPECT_TRUE(loader.idle().empty());
  EXPECT_EQ(loader.load(test::sample("block"), LengthUnit::Millimetre, "b")->faces().Extent(), 58);
  EXPECT_EQ(loader.started(), 2u);
}

TEST(LoaderProcess, AHelperThatHangsIsGivenUpAtTheTimeLimitAndKilled) {
  LoaderProcess loader(realHelper(1500ms));
  loader.load(test::sample("cylinder"), LengthUnit::Millimetre, "c");
  const pid_t helper = loader.idle().at(0);
  std::thread stop([helper] {
    awaitLoading(helper);
    kill(helper, SIGSTOP);  // as a loop would: no answer, ever
  });
  const auto start = std::chrono::steady_clock::now();
  const std::string error = errorOf(loader, test::corpus("machined_plate"), "Plate");
  stop.join();
  EXPECT_EQ(error, "loading Plate in the loader process did not finish within 1.5 s: given up");
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s);
  EXPECT_EQ(processState(helper), 0) << "killed and reaped";
  EXPECT_EQ(loader.load(test::sample("block"), LengthUnit::Millimetre, "b")->faces().Extent(), 58);
}

TEST(LoaderProcess, AHelperKilledWhileIdleIsNeverHandedAPart) {
  LoaderProcess loader(realHelper());
  loader.load(test::sample("cylinder"), LengthUnit::Millimetre, "c");
  const pid_t helper = loader.idle().at(0);
  kill(helper, SIGKILL);
  siginfo_t info{};  // until it can be reaped (every thread gone), without reaping it
  while (waitid(P_PID, helper, &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid != helper)
    std::this_thread::sleep_for(1ms);
  EXPECT_EQ(loader.load(test::sample("block"), LengthUnit::Millimetre, "b")->faces().Extent(), 58);
  EXPECT_EQ(loader.started(), 2u);
  EXPECT_EQ(processState(helper), 0) << "reaped";
}

TEST(LoaderProcess, EveryWayAHelperFailsIsOneErrorNamingThePart) {
  const std::string brep = test::sample("cylinder");
  {
    LoaderProcess crashesAtOnce(shellHelper("kill -SEGV $$"));
    EXPECT_THAT(errorOf(crashesAtOnce, brep), StartsWith("loading Bracket in the loader process crashed (SIGSEGV"));
  }
  {
    LoaderProcess crashesReading(shellHelper("head -c 100 >/dev/null; kill -ABRT $$"));
    EXPECT_THAT(errorOf(crashesReading, brep), StartsWith("loading Bracket in the loader process crashed (SIGABRT"));
  }
  {
    LoaderProcess exits(shellHelper("exit 3"));
    EXPECT_EQ(errorOf(exits, brep), "loading Bracket in the loader process stopped without an answer (exit code 3)");
  }
  {
    LoaderProcess garbage(shellHelper("head -c 100 >/dev/null; printf 'HGLAxxxxxxxxxxxxxxxx' >&0; sleep 5"));
    EXPECT_THAT(errorOf(garbage, brep), HasSubstr("in the loader process: its answer is garbled (a header of"));
  }
  {
    LoaderProcess sleeps(shellHelper("exec sleep 30", 300ms));
    EXPECT_EQ(errorOf(sleeps, brep), "loading Bracket in the loader process did not finish within 0.3 s: given up");
  }
  {
    LoaderProcess missing(LoaderProcess::Options{{"/nonexistent/hapticgrasp-loader"}, {}});
    EXPECT_EQ(errorOf(missing, brep),
              "the loader process cannot start (/nonexistent/hapticgrasp-loader): No such file or directory");
  }
  EXPECT_THROW(LoaderProcess(LoaderProcess::Options{}), std::invalid_argument);
}

// A build cancelled (FreeCAD closing) does not wait out a part in a loop: its load ends
// within 50 ms of the cancel, its helper killed, and the next load gets a new one.
TEST(LoaderProcess, ACancelledLoadEndsAtOnce) {
  LoaderProcess loader(shellHelper("exec sleep 30", 60s));
  std::atomic<bool> cancelled{false};
  std::thread cancel([&] {
    std::this_thread::sleep_for(200ms);
    cancelled = true;
  });
  const auto start = std::chrono::steady_clock::now();
  try {
    loader.load(test::sample("cylinder"), LengthUnit::Millimetre, "Bracket", {}, &cancelled);
    ADD_FAILURE() << "the load answered";
  } catch (const GeometryError& e) {
    EXPECT_EQ(std::string(e.what()), "loading Bracket in the loader process was stopped: the build was cancelled");
  }
  cancel.join();
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s) << "not the 60 s time limit";
  EXPECT_TRUE(loader.idle().empty());
  EXPECT_EQ(loader.started(), 1u);
}

TEST(LoaderProcess, ARecordedShapeIsCheckedForDisplayThere) {
  LoaderProcess loader(realHelper());
  const TopoDS_Shape block = test::readShape(std::string(HG_RESOURCES_DIR) + "/parts/block.brep");
  std::ostringstream binary(std::ios::binary);
  BinTools::Write(block, binary);
  EXPECT_EQ(loader.displayableText(binary.str(), LengthUnit::Millimetre, "Block"),
            displayableBrepText(binary.str(), LengthUnit::Millimetre, "Block"));
  try {
    loader.displayableText("not a shape", LengthUnit::Millimetre, "Block");
    ADD_FAILURE() << "given out";
  } catch (const GeometryError& e) {
    EXPECT_THAT(std::string(e.what()), StartsWith("is not a binary BREP"));
  }
  EXPECT_EQ(loader.started(), 1u);
  LoaderProcess crashes(shellHelper("head -c 10 >/dev/null; kill -SEGV $$"));
  try {
    crashes.displayableText(binary.str(), LengthUnit::Millimetre, "Block");
    ADD_FAILURE() << "given out";
  } catch (const GeometryError& e) {
    EXPECT_THAT(std::string(e.what()), StartsWith("checking Block for display in the loader process crashed (SIGSEGV"));
  }
}

TEST(LoaderProcess, ScenesWorkersLoadSideBySide) {
  LoaderProcess loader(realHelper());
  std::vector<PartModelPtr> parts(4);
  std::vector<std::thread> workers;
  const std::vector<std::string> names{"block", "cylinder", "loft", "block"};
  for (std::size_t i = 0; i < parts.size(); ++i)
    workers.emplace_back([&, i] { parts[i] = loader.load(test::sample(names[i]), LengthUnit::Millimetre, names[i]); });
  for (std::thread& w : workers) w.join();
  for (std::size_t i = 0; i < parts.size(); ++i) ASSERT_TRUE(parts[i]) << i;
  EXPECT_EQ(parts[0]->faces().Extent(), 58);
  EXPECT_EQ(parts[1]->faces().Extent(), 3);
  EXPECT_GE(loader.started(), 1u);
  EXPECT_LE(loader.started(), 4u);
  EXPECT_EQ(loader.idle().size(), loader.started());
}

// The workbench killed (FreeCAD crashed, or was killed): its helpers go too, idle or mid-load.
TEST(LoaderProcess, AHelperEndsWithItsParent) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t workbench = fork();
  ASSERT_GE(workbench, 0);
  if (workbench == 0) {  // the stand-in workbench: one idle helper, then killed
    close(fds[0]);
    auto* loader = new LoaderProcess(realHelper());  // never destroyed: killed below
    loader->load(test::sample("cylinder"), LengthUnit::Millimetre, "c");
    const pid_t helper = loader->idle().at(0);
    if (write(fds[1], &helper, sizeof helper) != sizeof helper) _exit(1);
    pause();
  }
  close(fds[1]);
  pid_t helper = -1;
  ASSERT_EQ(read(fds[0], &helper, sizeof helper), ssize_t(sizeof helper));
  close(fds[0]);
  EXPECT_NE(processState(helper), 0);
  kill(workbench, SIGKILL);
  waitpid(workbench, nullptr, 0);
  const auto start = std::chrono::steady_clock::now();
  while (processState(helper) != 0 && processState(helper) != 'Z' && std::chrono::steady_clock::now() - start < 10s)
    std::this_thread::sleep_for(10ms);
  const char state = processState(helper);
  EXPECT_TRUE(state == 0 || state == 'Z') << "the helper still runs: " << state;
}

}  // namespace
}  // namespace hg::geometry
