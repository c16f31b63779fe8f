// The STEP reference check that runs before OCCT's reader: circles and chains too deep for
// its recursion are refused in words; real files pass, far below the depth limit.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "geometry/step_references.hpp"
#include "file_fixtures.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::geometry {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using hg::test::readFile;

std::string part21(const std::string& data) {
  return "ISO-10303-21;\nHEADER;\nFILE_NAME('a.step','#1',(''),(''),'','','');\nENDSEC;\nDATA;\n" + data +
         "ENDSEC;\nEND-ISO-10303-21;\n";
}

// "#1 = ENTITY(#2); #2 = ENTITY(#3); ... #n = ENTITY();": a chain n entities deep.
std::string chain(int n) {
  std::string data;
  for (int i = 1; i < n; ++i) data += "#" + std::to_string(i) + " = ORIENTED_EDGE('',*,*,#" + std::to_string(i + 1) + ",.T.);\n";
  return data + "#" + std::to_string(n) + " = EDGE_CURVE('',*,*,*,.T.);\n";
}

TEST(StepReferences, AnEntityThatRefersToItselfIsNamed) {
  EXPECT_EQ(stepReferenceProblem(part21("#19 = EDGE_CURVE('',#1,#1,#1,.T.);\n#20 = ORIENTED_EDGE('',*,*,#20,.F.);\n")),
            "entity #20 (ORIENTED_EDGE) refers to itself");
}

TEST(StepReferences, ACircleIsNamedInItsOrder) {
  EXPECT_EQ(stepReferenceProblem(part21("#20 = ORIENTED_EDGE('',*,*,#21,.F.);\n#21 = (A(#22) B());\n"
                                        "#22 = ORIENTED_EDGE('',*,*,#20,.F.);\n")),
            "entities refer to each other in a circle: #20 (ORIENTED_EDGE) -> #21 -> #22 (ORIENTED_EDGE) -> #20");
}

TEST(StepReferences, NamesInStringsAndCommentsAreNotReferences) {
  const std::string text = part21("#1 = PRODUCT('#1 it''s; #1','x',\"0F\",(#2));\n/* #2 = X(#2); */\n#2 = PRODUCT_CONTEXT('');\n");
  EXPECT_EQ(stepReferenceProblem(text), "");
  EXPECT_EQ(stepReferenceDepth(text), 2u);
}

TEST(StepReferences, DepthIsTheLongestChainWhateverTheOrder) {
  // #1 -> #3 -> #2, written out of order, and #4 -> #2 beside it.
  const std::string text = part21("#2 = A();\n#4 = B(#2);\n#1 = C(#3, #4);\n#3 = D(#2);\n");
  EXPECT_EQ(stepReferenceDepth(text), 3u);
  EXPECT_EQ(stepReferenceDepth(part21("")), 0u);
}

TEST(StepReferences, AChainDeeperThanTheLimitIsRefused) {
  EXPECT_EQ(stepReferenceProblem(part21(chain(50)), 50), "");
  EXPECT_EQ(stepReferenceProblem(part21(chain(51)), 50),
            "references nest deeper than 50 entities, from #1 (ORIENTED_EDGE)");
  // Far deeper than any recursion would survive: the check itself does not recurse.
  EXPECT_EQ(stepReferenceDepth(part21(chain(300000))), 300000u);
}

TEST(StepReferences, DanglingReferencesAndGarbageAreLeftToOcct) {
  EXPECT_EQ(stepReferenceProblem(part21("#1 = A(#99);\n#2 = B(#);\n#3 = C('unclosed\n")), "");
  EXPECT_EQ(stepReferenceProblem("\xff\xfe#1=#2"), "");  // binary junk, then an entity without a type
  EXPECT_EQ(stepReferenceProblem("#1=A(#1"), "entity #1 (A) refers to itself");  // cut short
}

// Real files from other systems: no circle, and their depth far below the limit.
TEST(StepReferences, RealFilesAreFarBelowTheLimit) {
  const fs::path corpus = fs::path(HG_TEST_DATA_DIR) / "../corpus/external";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(corpus)) {
    if (entry.path().extension() != ".stp") continue;
    SCOPED_TRACE(entry.path().filename().string());
    const std::string text = readFile(entry.path());
    EXPECT_EQ(stepReferenceProblem(text), "");
    EXPECT_GT(stepReferenceDepth(text), 5u);
    EXPECT_LT(stepReferenceDepth(text), kMaxStepReferenceDepth / 20);
    ++files;
  }
  EXPECT_GE(files, 4);
}

// A file fuzz_step found: a flipped reference made an oriented edge its own edge element,
// and OCCT's reader recursed until the stack overflowed (SIGSEGV, with no stack left for a
// handler). (Its sibling, whose circle OCCT's reader makes itself from a damaged file, is
// caught by the fault stack: test_occt_faults.)
TEST(StepReferences, TheFileThatOverflowedOcctsReaderIsRefused) {
  const fs::path file = fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/step/crash_oriented_edge_refers_to_itself.step";
  try {
    PartModel::fromFile(file, LengthUnit::Millimetre);
    ADD_FAILURE() << "loaded";
  } catch (const GeometryError& e) {
    EXPECT_THAT(e.what(), HasSubstr("STEP file could not be read: entity #20 (ORIENTED_EDGE) refers to itself: "));
  }
}

}  // namespace
}  // namespace hg::geometry
