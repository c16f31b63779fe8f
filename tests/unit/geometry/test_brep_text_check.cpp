// The BREP text check that runs before OCCT's reader: every real text is followed entry by
// entry up to its shapes (so its grammar is OCCT's), and each kind of damage that would
// make the reader allocate without bound or recurse without end is refused in words.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <BRepBuilderAPI_Transform.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <STEPControl_Reader.hxx>
#include <TopoDS_Compound.hxx>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "geometry/brep_text_check.hpp"
#include "file_fixtures.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::geometry {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using hg::test::readFile;

std::string brepText(const TopoDS_Shape& shape) {
  std::ostringstream out;
  BRepTools::Write(shape, out);
  return out.str();
}

// The message checkBrepText throws for `text`, or "" if it passes.
std::string refusal(const std::string& text) {
  try {
    checkBrepText(text, "BREP text");
  } catch (const GeometryError& e) {
    return e.what();
  }
  return "";
}

// Replaces the first `from` after `after` by `to`.
std::string edited(std::string text, const std::string& after, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from, text.find(after));
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// Every file of the corpus (every surface and curve type OCCT has, as FreeCAD wrote them).
TEST(BrepTextCheck, EveryCorpusPartIsFollowedToItsShapes) {
  int parts = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(HG_TEST_DATA_DIR) / "../corpus/parts")) {
    SCOPED_TRACE(entry.path().filename().string());
    const std::string text = readFile(entry.path());
    EXPECT_TRUE(brepTextWalkedToShapes(text));
    EXPECT_EQ(refusal(text), "");
    ++parts;
  }
  EXPECT_GE(parts, 25);
}

// Real STEP files from elsewhere, read by OCCT and written again with their triangulations
// (nodes, UV nodes, triangles, polygons on triangulations) and their placements (locations).
TEST(BrepTextCheck, RealStepFilesMeshedAreFollowedToTheirShapes) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(HG_TEST_DATA_DIR) / "../corpus/external")) {
    if (entry.path().extension() != ".stp") continue;
    SCOPED_TRACE(entry.path().filename().string());
    STEPControl_Reader reader;
    ASSERT_EQ(reader.ReadFile(entry.path().c_str()), IFSelect_RetDone);
    reader.TransferRoots();
    const TopoDS_Shape shape = reader.OneShape();
    BRepMesh_IncrementalMesh(shape, 1.0);
    const std::string text = brepText(shape);
    ASSERT_NE(text.find("\nTriangulations 0"), text.find("\nTriangulations "));  // some were written
    EXPECT_TRUE(brepTextWalkedToShapes(text));
    EXPECT_EQ(refusal(text), "");
    ++files;
  }
  EXPECT_EQ(files, 4);
}

TEST(BrepTextCheck, ANumberOfPolesBeyondTheTextIsRefused) {
  const std::string text = readFile(fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/brep/oom_bspline_poles.brep");
  EXPECT_THAT(refusal(text), HasSubstr("its 3D curve 3 claims 1599999878 poles, more than the"));
}

// The banner is found as OCCT's reader finds it, a whole line: a first line that merely
// starts like one ("CASCADE Topology V3DBRep_DrawableShape") does not start the walk there.
TEST(BrepTextCheck, OnlyAWholeBannerLineStartsTheWalk) {
  const std::string text =
      readFile(fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/brep/oom_bspline_poles_after_false_banner.brep");
  ASSERT_EQ(text.rfind("CASCADE Topology V3DBRep_DrawableShape\n", 0), 0u);
  EXPECT_THAT(refusal(text), HasSubstr("its 3D curve 3 claims 1599999878 poles"));
}

// OCCT's reader carries on past an entry it cannot make (an unknown type reads nothing
// more), so the walk could lose its place: such a text is refused, naming the entry.
TEST(BrepTextCheck, AnEntryNotAsOcctWritesItIsRefused) {
  const std::string text = brepText(BRepPrimAPI_MakeCylinder(5, 10).Shape());
  EXPECT_EQ(refusal(edited(text, "\nCurves ", "\n1 ", "\n12 ")),
            "BREP text could not be read: its 3D curve 2 is not as OCCT writes it");
  EXPECT_EQ(refusal(edited(text, "", "Surfaces ", "Surfaces? ")),
            "BREP text could not be read: its Surfaces header is not as OCCT writes it");
}

TEST(BrepTextCheck, ATriangulationLargerThanTheTextIsRefused) {
  const TopoDS_Shape cylinder = BRepPrimAPI_MakeCylinder(5, 10).Shape();
  BRepMesh_IncrementalMesh(cylinder, 0.5);
  const std::string text = brepText(cylinder);
  ASSERT_TRUE(brepTextWalkedToShapes(text));
  const std::size_t header = text.find("\nTriangulations ");
  const std::size_t entry = text.find('\n', header + 1) + 1;  // "<nodes> <triangles> <uv> ..."
  std::string huge = text;
  huge.replace(entry, huge.find(' ', entry) - entry, "900000000");
  EXPECT_THAT(refusal(huge), HasSubstr("its triangulation 1 claims 900000000 nodes"));
}

// A trimmed curve of a trimmed curve of ...: OCCT's reader recurses once a level.
TEST(BrepTextCheck, CurvesNestedTooDeepAreRefused) {
  const std::string text = brepText(BRepPrimAPI_MakeCylinder(5, 10).Shape());
  std::string nested;
  for (int i = 0; i < 100; ++i) nested += "8 0 1 ";
  EXPECT_THAT(refusal(edited(text, "\nCurves ", "\n1 ", "\n" + nested + "1 ")),
              HasSubstr("its 3D curve 2 nests curves and surfaces more than 64 deep"));
  std::string shallow;
  for (int i = 0; i < 3; ++i) shallow += "8 0 1 ";
  EXPECT_TRUE(brepTextWalkedToShapes(edited(text, "\nCurves ", "\n1 ", "\n" + shallow + "1 ")));
}

TEST(BrepTextCheck, ALocationRaisedTooFarIsRefused) {
  TopoDS_Compound placed;
  BRep_Builder builder;
  builder.MakeCompound(placed);
  const TopoDS_Shape cylinder = BRepPrimAPI_MakeCylinder(5, 10).Shape();
  gp_Trsf shift;
  shift.SetTranslation(gp_Vec(20, 0, 0));
  builder.Add(placed, cylinder.Moved(TopLoc_Location(shift)));
  builder.Add(placed, cylinder.Moved(TopLoc_Location(shift).Powered(2)));
  builder.Add(placed, cylinder.Moved(TopLoc_Location(shift) * TopLoc_Location(shift).Inverted().Powered(3)));
  const std::string text = brepText(placed);
  ASSERT_TRUE(brepTextWalkedToShapes(text));
  const std::size_t compound = text.find("\n2 ", text.find("\nLocations "));
  ASSERT_NE(compound, std::string::npos) << text.substr(0, 600);
  std::string raised = text;
  const std::size_t power = raised.find(' ', raised.find_first_not_of(' ', compound + 3)) + 1;  // "2  <datum> <power>"
  raised.replace(power, raised.find(' ', power) - power, "5000000");
  EXPECT_THAT(refusal(raised), HasSubstr("its location 3 raises location 2 to the power 5000000"));
}

// OCCT reads a section's name into a buffer of 255 characters.
TEST(BrepTextCheck, AWordLongerThanTheReaderReadsIsRefused) {
  const std::string text = brepText(BRepPrimAPI_MakeCylinder(5, 10).Shape());
  EXPECT_THAT(refusal(edited(text, "", "Curves ", std::string(300, 'C') + " ")),
              HasSubstr("it holds a word of 300 characters (at most 254 are read)"));
}

}  // namespace
}  // namespace hg::geometry
