// Curves on faces with the parameter ranges OCCT's algorithms do not survive: the two
// damaged parts fuzz_brep found are named, real parts pass.
#include <gtest/gtest.h>

#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>

#include <filesystem>
#include <string>

#include "geometry/curve_on_face.hpp"

namespace hg::geometry {
namespace {

namespace fs = std::filesystem;

TopoDS_Shape readSeed(const std::string& name) {
  TopoDS_Shape shape;
  BRep_Builder builder;
  const fs::path path = fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/brep" / name;
  EXPECT_TRUE(BRepTools::Read(shape, path.c_str(), builder)) << path;
  return shape;
}

std::string emptyRanges(const TopoDS_Shape& shape) {
  return firstCurveOnFace(shape, [](const CurveOnFace& c) { return c.emptyRange() ? "is empty" : ""; });
}

TEST(CurveOnFace, RealShapesHaveNeither) {
  for (const TopoDS_Shape& shape : {BRepPrimAPI_MakeCylinder(50, 400).Shape(), BRepPrimAPI_MakeTorus(30, 10).Shape()}) {
    EXPECT_EQ(emptyRanges(shape), "");
    EXPECT_EQ(runawayParameters(shape), "");
  }
}

// The bottom circle of a cylinder on [0, 0] on the side face (a flipped byte).
TEST(CurveOnFace, AnEmptyRangeIsNamed) {
  const TopoDS_Shape shape = readSeed("timeout_empty_pcurve_range.brep");
  EXPECT_EQ(emptyRanges(shape), "edge 3 is empty on face 1");
  EXPECT_EQ(runawayParameters(shape), "");  // empty is not round: the part still loads (mesh)
}

// A seam on a torus on [0, 6.1e15] (a digit lost): 1e15 times round.
TEST(CurveOnFace, ACurveThatRunsRoundAPeriodicFaceIsNamed) {
  const TopoDS_Shape shape = readSeed("timeout_pcurve_beyond_periods.brep");
  EXPECT_EQ(runawayParameters(shape), "edge 2 runs more than 1000 times round on face 1");
}

// A sphere's seam on [4.7, 6.9e16] in latitude, whose range is [-pi/2, pi/2] (a lost digit):
// meshing the face in the crossing search never ended.
TEST(CurveOnFace, ACurveThatRunsFarOffABoundedDirectionIsNamed) {
  EXPECT_EQ(runawayParameters(readSeed("timeout_sphere_seam_runs_off.brep")),
            "edge 2 runs 1000 times its size off on face 1");
}

}  // namespace
}  // namespace hg::geometry
