// OCCT's faults as errors in a process that owns its handlers, Ctrl-C left alone.
//
// OCC_CATCH_SIGNALS is active only with OCC_CONVERT_SIGNALS, as in part_model.cpp
// (core/CMakeLists.txt).
#define OCC_CONVERT_SIGNALS
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <csignal>
#include <fstream>
#include <sstream>
#include <string>

#include "hapticgrasp/geometry/occt_faults.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/sanitized.hpp"

#if defined(HG_SANITIZED) && !defined(__SANITIZE_THREAD__)
#include <sanitizer/lsan_interface.h>
#endif

namespace hg::geometry {
namespace {

using ::testing::HasSubstr;

// What a fault under OCC_CATCH_SIGNALS becomes: the message of the Standard_Failure thrown.
std::string faultMessage(int signal) {
  try {
    OCC_CATCH_SIGNALS
    raise(signal);
  } catch (const Standard_Failure& e) {
    return e.GetMessageString();
  }
  return "no exception";
}

TEST(OcctFaults, ASegmentationFaultBecomesAStandardFailure) {
  catchOcctFaults();
  EXPECT_THAT(faultMessage(SIGSEGV), HasSubstr("SIGSEGV"));
}

TEST(OcctFaults, ABusErrorBecomesAStandardFailure) {
  catchOcctFaults();
  EXPECT_THAT(faultMessage(SIGBUS), HasSubstr("SIGBUS"));
}

// Each fault is counted once, however often the handlers are put in (every test here does).
TEST(OcctFaults, EachFaultIsCountedOnce) {
  catchOcctFaults();
  catchOcctFaults();
  const unsigned long before = occtFaultsCaught();
  EXPECT_THAT(faultMessage(SIGSEGV), HasSubstr("SIGSEGV"));
  EXPECT_THAT(faultMessage(SIGBUS), HasSubstr("SIGBUS"));
  EXPECT_EQ(occtFaultsCaught(), before + 2);
}

// A recursion that never ends, as OCCT's STEP reader did on an ORIENTED_EDGE that was its
// own edge element: each frame keeps a little of the stack, so no compiler turns it into a
// loop.
volatile bool keepRecursing = true;  // always true: the compiler cannot see that it is
int recurseForever(int depth) {
  volatile char frame[256];
  frame[depth % sizeof frame] = static_cast<char>(depth);
  return keepRecursing ? recurseForever(depth + 1) + frame[0] : 0;
}

TEST(OcctFaults, AStackOverflowOnAThreadWithAFaultStackBecomesAStandardFailure) {
  catchOcctFaults();
#if defined(HG_SANITIZED) && !defined(__SANITIZE_THREAD__)
  __lsan::ScopedDisabler faultLeavesItsFramesBehind;  // as below
#endif
  const FaultStack handlerHasAStack;
  std::string message = "no exception";
  try {
    OCC_CATCH_SIGNALS
    recurseForever(0);
  } catch (const Standard_Failure& e) {
    message = e.GetMessageString();
  }
  EXPECT_THAT(message, HasSubstr("SIGSEGV"));
  // And the thread's stack works as before: a fault after the overflow is caught too.
  EXPECT_THAT(faultMessage(SIGSEGV), HasSubstr("SIGSEGV"));
}

// A damaged STEP file fuzz_step found: OCCT's reader, recovering from its errors, made an
// oriented edge refer to itself (the text has no such circle: step_references cannot see
// it) and recursed until the stack ran out. The reader's fault stack turns that into one
// error.
TEST(OcctFaults, AStepFileThatOverflowsTheReadersStackIsRefused) {
  catchOcctFaults();
#if defined(HG_SANITIZED) && !defined(__SANITIZE_THREAD__)
  __lsan::ScopedDisabler faultLeavesItsFramesBehind;  // as below
#endif
  try {
    PartModel::fromFile(std::string(HG_TEST_DATA_DIR) + "/../fuzz/corpus/step/crash_oriented_edge_circle.step",
                        LengthUnit::Millimetre);
    ADD_FAILURE() << "loaded";
  } catch (const GeometryError& e) {
    // OCCT names this fault "System Signal received, check interrupt".
    EXPECT_THAT(e.what(), HasSubstr("could not read "));
    EXPECT_THAT(e.what(), HasSubstr("crash_oriented_edge_circle.step: System Signal received"));
  }
}

// A part whose BRepCheck faults at address 0 (fuzz_brep; the input is in its corpus). The
// fault was caught in PartModel::load, past the checks' frames: their future was lost and,
// with `parallel`, the crossing search went on reading a shape whose frame was gone. Now
// each check catches its own: the part is refused with one line, in either mode.
TEST(OcctFaults, AFaultInThePartChecksIsCaughtByTheChecks) {
  catchOcctFaults();
  std::ifstream in(std::string(HG_TEST_DATA_DIR) + "/../fuzz/corpus/brep/leak_fault_in_checks.brep");
  std::stringstream text;
  text << in.rdbuf();
  ASSERT_FALSE(text.str().empty());
  for (const bool parallel : {false, true}) {
    SCOPED_TRACE(parallel ? "parallel" : "one thread");
#if defined(HG_SANITIZED) && !defined(__SANITIZE_THREAD__)
    // The fault is raised in the middle of OCCT's code and leaves by an exception thrown
    // from the signal handler: what the frames it abandons had allocated (a few hundred
    // bytes, once per faulty part) is never freed. That is the price of surviving the fault,
    // not a leak of ours; LeakSanitizer is told to ignore what this load allocates.
    __lsan::ScopedDisabler faultLeavesItsFramesBehind;
#endif
    PartLoadOptions options;
    options.parallel = parallel;
    EXPECT_THROW(PartModel::fromBrepText(text.str(), LengthUnit::Millimetre, "fault", options), GeometryError);
  }
}

void onInterrupt(int) {}

TEST(OcctFaults, InterruptHangUpAndQuitKeepTheirHandlers) {
  for (const int kept : {SIGINT, SIGHUP, SIGQUIT}) std::signal(kept, onInterrupt);
  catchOcctFaults();
  for (const int kept : {SIGINT, SIGHUP, SIGQUIT}) {
    struct sigaction now {};
    sigaction(kept, nullptr, &now);
    EXPECT_EQ(now.sa_handler, &onInterrupt) << "signal " << kept;
  }
}

}  // namespace
}  // namespace hg::geometry
