// firstValidityProblem: BRepCheck_Analyzer's verdict, also on faces with many wires (where
// it classifies the wires through their boxes), and the problem in words.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <GC_MakeCircle.hxx>
#include <TopoDS.hxx>
#include <gp_Circ.hxx>

#include <filesystem>
#include <string>

#include "hapticgrasp/geometry/shape_validity.hpp"
#include "test_shapes.hpp"

namespace hg::geometry {
namespace {

using ::testing::HasSubstr;

// A 100 mm square with `holes` round holes of radius 1 mm on a grid, as the sample plate's
// faces are; `stray` of the wires are put outside the square, `unturned` are not reversed
// (so they are not holes).
TopoDS_Face squareWithHoles(int holes, int stray = 0, int unturned = 0) {
  const TopoDS_Wire outline =
      BRepBuilderAPI_MakePolygon(gp_Pnt(0, 0, 0), gp_Pnt(100, 0, 0), gp_Pnt(100, 100, 0), gp_Pnt(0, 100, 0), true).Wire();
  BRepBuilderAPI_MakeFace face(gp_Pln(gp::XOY()), outline);
  for (int i = 0; i < holes; ++i) {
    const double x = 5 + 10 * (i % 9), y = 5 + 10 * (i / 9) + (i < stray ? 200 : 0);
    const gp_Circ circle(gp_Ax2(gp_Pnt(x, y, 0), gp::DZ()), 1);
    TopoDS_Wire wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire();
    if (i >= unturned) wire.Reverse();
    face.Add(wire);
  }
  return face.Face();
}

bool analyzerSaysValid(const TopoDS_Shape& shape) { return BRepCheck_Analyzer(shape).IsValid(); }

TEST(ShapeValidity, AgreesWithTheAnalyzerOnFacesWithManyHoles) {
  for (const int holes : {3, 40}) {  // both sides of the many-wires path
    SCOPED_TRACE(std::to_string(holes) + " holes");
    const TopoDS_Face good = squareWithHoles(holes);
    ASSERT_TRUE(analyzerSaysValid(good));
    EXPECT_FALSE(firstValidityProblem(good));
    const TopoDS_Face stray = squareWithHoles(holes, 1);  // a hole outside the outline
    ASSERT_FALSE(analyzerSaysValid(stray));
    const auto strayProblem = firstValidityProblem(stray);
    ASSERT_TRUE(strayProblem);
    EXPECT_EQ(strayProblem->status, BRepCheck_InvalidImbricationOfWires);
    const TopoDS_Face unturned = squareWithHoles(holes, 0, 1);  // a hole that is not one
    ASSERT_FALSE(analyzerSaysValid(unturned));
    EXPECT_TRUE(firstValidityProblem(unturned));
  }
}

TEST(ShapeValidity, SamplePartsAreValid) {
  for (const char* name : {"cylinder.brep", "block.brep", "loft.brep", "plate.brep"}) {
    SCOPED_TRACE(name);
    const TopoDS_Shape shape = test::readShape(std::filesystem::path(HG_RESOURCES_DIR) / "parts" / name);
    const auto problem = firstValidityProblem(shape);
    EXPECT_FALSE(problem) << describe(*problem, shape);
  }
  EXPECT_FALSE(firstValidityProblem(test::helicalThread()));
}

TEST(ShapeValidity, ASelfIntersectingWireIsNamedByItsFace) {
  const TopoDS_Shape loop = test::loopPrism();
  const auto problem = firstValidityProblem(loop);
  ASSERT_TRUE(problem);
  EXPECT_THAT(describe(*problem, loop), ::testing::MatchesRegex("self-intersecting wire in face [0-9]+"));
}

TEST(ShapeValidity, OtherProblemsNameTheSubShapeAndTheStatus) {
  const TopoDS_Face stray = squareWithHoles(3, 1);
  const auto problem = firstValidityProblem(stray);
  ASSERT_TRUE(problem);
  EXPECT_EQ(describe(*problem, stray), "face 1: BRepCheck_InvalidImbricationOfWires");
}

}  // namespace
}  // namespace hg::geometry
