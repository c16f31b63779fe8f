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
#include <string>

#include "hapticgrasp/geometry/occt_faults.hpp"

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
