// UvDomain: whether (u, v) lies in a trimmed face, against OCCT's own face classifier,
// and across the tolerance gaps a valid face's pcurves may leave between them.
#include "geometry/exact/uv_domain.hpp"

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Geom2d_Line.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <GCE2d_MakeSegment.hxx>
#include <Geom_Plane.hxx>
#include <gtest/gtest.h>

#include "test_shapes.hpp"

namespace hg::geometry::exact {
namespace {
using namespace hg::test;

// Counts the grid points of the face's UV box (grown by a tenth) where UvDomain and
// BRepClass_FaceClassifier disagree, leaving out the points the classifier puts on the
// boundary (within a millionth of the box).
int disagreements(const TopoDS_Face& face, int grid = 41) {
  const UvDomain domain(face);
  double u0, u1, v0, v1;
  BRepTools::UVBounds(face, u0, u1, v0, v1);
  const double du = 0.1 * (u1 - u0), dv = 0.1 * (v1 - v0);
  const double onTolerance = 1e-6 * std::max(u1 - u0, v1 - v0);
  int wrong = 0;
  for (int i = 0; i <= grid; ++i)
    for (int j = 0; j <= grid; ++j) {
      const gp_Pnt2d uv(u0 - du + (u1 - u0 + 2 * du) * (i + 0.37) / (grid + 1),
                        v0 - dv + (v1 - v0 + 2 * dv) * (j + 0.61) / (grid + 1));
      const BRepClass_FaceClassifier occt(face, uv, onTolerance);
      if (occt.State() == TopAbs_ON) continue;
      wrong += domain.contains(uv.X(), uv.Y()) != (occt.State() == TopAbs_IN);
    }
  return wrong;
}

TEST(UvDomain, AgreesWithOcctOnEveryFaceOfPartsOfEverySurfaceType) {
  const std::vector<PartModelPtr> parts{drilledBlockPart(), spherePart(), loftPart(), revolvedSplinePart(),
                                        conePart(), torusPart(30, 10), trimmedSurfacePart(), thickLoftPart(),
                                        sweptTubePart(), cylinderPart()};
  for (const PartModelPtr& part : parts)
    for (TopExp_Explorer ex(part->shape(), TopAbs_FACE); ex.More(); ex.Next())
      EXPECT_EQ(disagreements(TopoDS::Face(ex.Current())), 0) << part->name();
}

TEST(UvDomain, AFaceWithAHoleExcludesTheHole) {
  const PartModelPtr block = drilledBlockPart();
  int withHoles = 0;
  for (TopExp_Explorer ex(block->shape(), TopAbs_FACE); ex.More(); ex.Next()) {
    const TopoDS_Face& face = TopoDS::Face(ex.Current());
    int wires = 0;
    for (TopExp_Explorer w(face, TopAbs_WIRE); w.More(); w.Next()) ++wires;
    if (wires < 2) continue;
    ++withHoles;
    EXPECT_EQ(disagreements(face, 81), 0);
  }
  EXPECT_GT(withHoles, 0);
}

// The unit square of a plane whose top edge's pcurve is moved by `shift` in v: its ends
// no longer meet the sides' (a gap within the edge's tolerance, as in the corpus's
// makeThickness cup, where a ray through the gap used to count one side only).
TopoDS_Face squareWithGap(double shift) {
  const Handle(Geom_Plane) plane = new Geom_Plane(gp::XOY());
  TopoDS_Face face = BRepBuilderAPI_MakeFace(plane, 0, 1, 0, 1, 1e-7);
  BRep_Builder builder;
  for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More(); ex.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(ex.Current());
    double first, last;
    const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
    const gp_Pnt2d a = pcurve->Value(first), b = pcurve->Value(last);
    if (std::abs(a.Y() - 1) > 1e-9 || std::abs(b.Y() - 1) > 1e-9) continue;
    const Handle(Geom2d_Curve) moved = new Geom2d_Line(gp_Pnt2d(0, 1 + shift), gp_Dir2d(1, 0));
    builder.UpdateEdge(edge, moved, face, 2 * std::abs(shift));
    builder.Range(edge, face, a.X(), b.X());
  }
  return face;
}

TEST(UvDomain, ClosesTheGapsBetweenPcurvesThatMeetOnlyWithinTolerance) {
  // Top pcurve lowered: above it is outside, though a ray there still meets the right side.
  const UvDomain lowered(squareWithGap(-0.004));
  EXPECT_FALSE(lowered.contains(0.5, 0.998));
  EXPECT_TRUE(lowered.contains(0.5, 0.994));
  // Raised: the band below it is inside, though a ray there passes above the right side.
  const UvDomain raised(squareWithGap(0.004));
  EXPECT_TRUE(raised.contains(0.5, 1.002));
  EXPECT_FALSE(raised.contains(0.5, 1.006));
  EXPECT_TRUE(raised.contains(0.5, 0.5));
  EXPECT_FALSE(raised.contains(1.5, 0.5));
}

TEST(UvDomain, RectOutsideOnlyWhenNoBoundaryIsNearAndTheCentreIsOut) {
  const UvDomain square(squareWithGap(0));
  EXPECT_TRUE(square.rectOutside(1.5, 2, 0.2, 0.4));
  EXPECT_FALSE(square.rectOutside(0.2, 0.4, 0.2, 0.4));   // inside
  EXPECT_FALSE(square.rectOutside(0.9, 1.2, 0.2, 0.4));   // straddles the right side
  EXPECT_FALSE(square.rectOutside(-1, 2, -1, 2));         // holds the whole face
  EXPECT_FALSE(square.contains(0.5, -0.5));
}

}  // namespace
}  // namespace hg::geometry::exact
