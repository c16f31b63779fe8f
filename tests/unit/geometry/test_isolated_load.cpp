// A load in a child process: its answer, or one GeometryError saying how the child ended.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <string>
#include <vector>

#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/isolated_load.hpp"
#include "hapticgrasp/sanitized.hpp"

namespace hg::geometry {
namespace {

using ::testing::HasSubstr;

std::string errorOf(const std::function<std::string()>& work, const IsolationLimits& limits = {}) {
  try {
    isolatedLoad("part.step: loading the part", work, limits);
  } catch (const GeometryError& e) {
    return e.what();
  }
  ADD_FAILURE() << "the load answered; expected a GeometryError";
  return "";
}

TEST(IsolatedLoad, AnswersWhatTheWorkReturned) {
  EXPECT_EQ(isolatedLoad("x", [] { return std::string("faces 3, edges 3\n"); }),
            "faces 3, edges 3\n");
}

TEST(IsolatedLoad, AnswerLongerThanAPipeHoldsArrivesWhole) {
  std::string big;
  for (int i = 0; big.size() < (4 << 20); ++i) big += std::to_string(i) + ' ';
  EXPECT_EQ(isolatedLoad("x", [&] { return big; }), big);
}

TEST(IsolatedLoad, TheWorksErrorPassesThroughAsItsMessage) {
  EXPECT_EQ(
      errorOf([]() -> std::string { throw GeometryError("STEP file holds no shape: part.step"); }),
      "STEP file holds no shape: part.step");
}

TEST(IsolatedLoad, ACrashIsNamedWithItsSignal) {
  EXPECT_THAT(errorOf([]() -> std::string {
                raise(SIGSEGV);
                return "";
              }),
              HasSubstr("part.step: loading the part crashed (SIGSEGV, Segmentation fault)"));
}

TEST(IsolatedLoad, AHangIsGivenUpAtTheTimeLimit) {
  IsolationLimits limits;
  limits.time = std::chrono::milliseconds(300);
  EXPECT_EQ(errorOf(
                []() -> std::string {
                  for (;;) pause();
                },
                limits),
            "part.step: loading the part did not finish within 0.3 s: given up");
}

TEST(IsolatedLoad, ATimeLimitOfZeroWaitsAsLongAsItTakes) {
  IsolationLimits limits;
  limits.time = std::chrono::milliseconds::zero();
  EXPECT_EQ(isolatedLoad(
                "x",
                [] {
                  usleep(100'000);
                  return std::string("slow part");
                },
                limits),
            "slow part");
}

TEST(IsolatedLoad, MemoryBeyondTheLimitIsRefused) {
#ifdef HG_SANITIZED
  GTEST_SKIP() << "a sanitized build sets no address-space limit (its shadow memory takes terabytes)";
#endif
  IsolationLimits limits;
  limits.memoryBytes = 1ull << 30;
  EXPECT_EQ(errorOf(
                []() -> std::string {
                  std::vector<char> huge(std::size_t(2) << 30, 1);
                  return std::to_string(huge.back());
                },
                limits),
            "part.step: loading the part needs more than 1 GiB of memory: given up");
}

TEST(IsolatedLoad, AChildThatExitsWithoutAnswerIsSaidSo) {
  // As OCCT does when a fault finds no OCC_CATCH_SIGNALS: it prints and exits.
  EXPECT_EQ(errorOf([]() -> std::string { _exit(1); }),
            "part.step: loading the part stopped without an answer (exit code 1)");
}

TEST(IsolatedLoad, TheParentGoesOnAfterEachEnding) {
  EXPECT_THAT(errorOf([]() -> std::string {
                raise(SIGBUS);
                return "";
              }),
              HasSubstr("crashed (SIGBUS"));
  EXPECT_EQ(isolatedLoad("x", [] { return std::string("next part"); }), "next part");
}

}  // namespace
}  // namespace hg::geometry
