// Curves on faces with the parameter ranges OCCT's algorithms do not survive: the two
// damaged parts fuzz_brep found are named, real parts pass; so are edges without a 3D curve.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <Geom_Line.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <TopExp_Explorer.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <gp_Trsf.hxx>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "geometry/curve_on_face.hpp"
#include "test_shapes.hpp"

namespace hg::geometry {
namespace {

namespace fs = std::filesystem;

TopoDS_Shape readSeed(const std::string& name) {
  return test::readShape(fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/brep" / name);
}

// A copy of a 50 x 400 mm cylinder, `change` applied to each of its circles (edge, 3D
// curve, its range): the damage under test, made by hand.
TopoDS_Shape cylinderWithCircles(
    const std::function<void(const TopoDS_Edge&, const Handle(Geom_Curve)&, double, double)>& change) {
  const TopoDS_Shape cylinder = BRepBuilderAPI_Copy(BRepPrimAPI_MakeCylinder(50, 400).Shape()).Shape();
  TopTools_IndexedMapOfShape edges;
  TopExp::MapShapes(cylinder, TopAbs_EDGE, edges);
  for (int i = 1; i <= edges.Extent(); ++i) {
    double first = 0, last = 0;
    const TopoDS_Edge& edge = TopoDS::Edge(edges(i));
    const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, first, last);
    if (curve->IsPeriodic()) change(edge, curve, first, last);
  }
  return cylinder;
}

std::string emptyRanges(const TopoDS_Shape& shape) {
  return firstCurveOnFace(shape, [](const CurveOnFace& c) { return c.emptyRange() ? "is empty" : ""; });
}

// A sphere's poles and a cone's apex are degenerate edges, which have no 3D curve.
TEST(CurveOnFace, RealShapesHaveNeither) {
  for (const TopoDS_Shape& shape : {BRepPrimAPI_MakeCylinder(50, 400).Shape(), BRepPrimAPI_MakeTorus(30, 10).Shape(),
                                    BRepPrimAPI_MakeSphere(20).Shape(), BRepPrimAPI_MakeCone(50, 0, 100).Shape()}) {
    EXPECT_EQ(emptyRanges(shape), "");
    EXPECT_EQ(damagedGeometry(shape), "");
  }
}

// The bottom circle of a cylinder on [0, 0] on the side face (a flipped byte).
TEST(CurveOnFace, AnEmptyRangeIsNamed) {
  const TopoDS_Shape shape = readSeed("timeout_empty_pcurve_range.brep");
  EXPECT_EQ(emptyRanges(shape), "edge 3 is empty on face 1");
  EXPECT_EQ(damagedGeometry(shape), "");  // empty is not round: the part still loads (mesh)
}

// A seam on a torus on [0, 6.1e15] (a digit lost): 1e15 times round.
TEST(CurveOnFace, ACurveThatRunsRoundAPeriodicFaceIsNamed) {
  const TopoDS_Shape shape = readSeed("timeout_pcurve_beyond_periods.brep");
  EXPECT_EQ(damagedGeometry(shape), "edge 2 runs more than 1000 times round on face 1");
}

// A sphere's seam on [4.7, 6.9e16] in latitude, whose range is [-pi/2, pi/2] (a lost digit):
// meshing the face in the crossing search never ended.
TEST(CurveOnFace, ACurveThatRunsFarOffABoundedDirectionIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("timeout_sphere_seam_runs_off.brep")),
            "edge 2 runs 1000 times its size off on face 1");
}

// A cone's seam at v = -4.4e101 (a run of fours): a cone's length is unbounded (OCCT says
// +-2e100), and BRepMesh laid nodes down the whole of it until memory ran out.
TEST(CurveOnFace, ACurveFarDownAnUnboundedDirectionIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("oom_cone_seam_far_down.brep")),
            "edge 2 runs 1000 times the part's size off on face 1");
}

// BRepMesh tessellates an edge without a 3D curve through a curve on a face: on a damaged
// cylinder (a curve index past the table's end) it never ended.
TEST(CurveOnFace, AnEdgeWithoutA3dCurveIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("timeout_edge_without_3d_curve.brep")), "edge 3 has no 3D curve");
  const TopoDS_Shape box = BRepBuilderAPI_Copy(BRepPrimAPI_MakeBox(10, 20, 30).Shape()).Shape();
  TopTools_IndexedMapOfShape edges;
  TopExp::MapShapes(box, TopAbs_EDGE, edges);
  BRep_Builder().UpdateEdge(TopoDS::Edge(edges(5)), Handle(Geom_Curve)(), 1e-7);
  EXPECT_EQ(damagedGeometry(box), "edge 5 has no 3D curve");
}

// A cylinder's top circle on [0, 618] (a word for a digit), 98 times round: BRepMesh's
// Delaunay triangulation of the side face never ended.
TEST(CurveOnFace, AnEdgeThatGoesRoundItsCurveMoreThanOnceIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("timeout_edge_turns_98_times.brep")),
            "edge 1 goes 98.4 times round its curve (an edge goes round once at most)");
}

// A cone's seam written with one curve on the face twice ("2 2" for "2 3"): BRepMesh's
// preprocessing inserted points on it until memory ran out. Real seams (the shapes of
// RealShapesHaveNeither) have two.
TEST(CurveOnFace, ASeamWhoseTwoCurvesAreOneIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("oom_seam_on_itself.brep")), "edge 2 is a seam whose two curves are one on face 1");
  // Two curves on the same line: a cylinder's seam given a copy of its first curve twice.
  const TopoDS_Shape cylinder = BRepBuilderAPI_Copy(BRepPrimAPI_MakeCylinder(50, 400).Shape()).Shape();
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(cylinder, TopAbs_FACE, faces);
  const TopoDS_Face& side = TopoDS::Face(faces(1));
  for (TopExp_Explorer e(side, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    if (!BRep_Tool::IsClosed(edge, side)) continue;
    double first = 0, last = 0;
    const Handle(Geom2d_Curve) curve = BRep_Tool::CurveOnSurface(edge, side, first, last);
    BRep_Builder().UpdateEdge(edge, curve, Handle(Geom2d_Curve)::DownCast(curve->Copy()), side, 1e-7);
  }
  EXPECT_EQ(damagedGeometry(cylinder), "edge 2 is a seam whose two curves coincide on face 1");
}

// A damaged loft (a pole of its bottom edge 4 km off; a fuzz input): BRepMesh at 0.01 mm
// ran for minutes on its side. Edge 2 has an empty range on the side, face 1, so OCCT
// cannot compare its curves there; edge 3 lies 17.7 mm off face 3, a plane, which is left
// out. A damaged cone's bottom circle runs 11.9 mm off its side. A real part's edges lie on
// their faces.
TEST(CurveOnFace, CurvedFacesWhoseEdgesStrayFromThemAreFound) {
  const std::vector<FaceOffItsEdges> off = curvedFacesOffTheirEdges(readSeed("mesh_curve_off_face_a.brep"), 1.0);
  ASSERT_EQ(off.size(), 1u);
  EXPECT_EQ(off[0].face, 1);
  EXPECT_EQ(off[0].edge, 2);
  EXPECT_FALSE(std::isfinite(off[0].distance));
  const std::vector<FaceOffItsEdges> cone = curvedFacesOffTheirEdges(readSeed("mesh_cone_diagonal_pcurve_a.brep"), 1.0);
  ASSERT_EQ(cone.size(), 1u);
  EXPECT_EQ(cone[0].face, 1);
  EXPECT_EQ(cone[0].edge, 3);
  EXPECT_NEAR(cone[0].distance, 11.93, 0.01);
  for (const TopoDS_Shape& shape : {BRepPrimAPI_MakeCylinder(50, 400).Shape(), BRepPrimAPI_MakeTorus(30, 10).Shape(),
                                    BRepPrimAPI_MakeSphere(20).Shape(), BRepPrimAPI_MakeCone(50, 0, 100).Shape(),
                                    readSeed("loft.brep")})
    EXPECT_TRUE(curvedFacesOffTheirEdges(shape, 1e-6).empty());
  // A cylinder's top circle lifted 2 mm off its side face: found at less than 2, not beyond.
  const TopoDS_Shape cylinder =
      cylinderWithCircles([](const TopoDS_Edge&, const Handle(Geom_Curve)& curve, double first, double) {
        if (curve->Value(first).Z() > 1) curve->Translate(gp_Vec(0, 0, 2));
      });
  const std::vector<FaceOffItsEdges> lifted = curvedFacesOffTheirEdges(cylinder, 1.9);
  ASSERT_FALSE(lifted.empty());
  EXPECT_NEAR(lifted[0].distance, 2.0, 1e-4);  // OCCT adds 1e-5 of it, to be safe
  EXPECT_TRUE(curvedFacesOffTheirEdges(cylinder, 2.1).empty());
}

// A placed face's edges lie on it: the 3D curve and the curve on the face are compared in
// the shape's frame. (Compared in the surface's own frame, every edge of a cylinder moved
// by 100 mm strayed by 100 mm, and four holes of a valid plate in the corpus by 14 and 81.)
TEST(CurveOnFace, APlacedFacesEdgesLieOnIt) {
  gp_Trsf placement;
  placement.SetTranslation(gp_Vec(100, 0, 0));
  const TopoDS_Shape moved = BRepPrimAPI_MakeCylinder(50, 400).Shape().Moved(TopLoc_Location(placement));
  EXPECT_TRUE(curvedFacesOffTheirEdges(moved, 1e-6).empty());
  const TopoDS_Shape plate = readSeed("../../../corpus/parts/machined_plate.brep");
  EXPECT_TRUE(curvedFacesOffTheirEdges(plate, 1e-6).empty());
}

// The turns of an edge's own range, made here: once and a writer's round-off load; twice
// does not.
TEST(CurveOnFace, AnEdgeMayGoRoundOnceWithRoundOff) {
  for (const double turns : {1.0, 1.005, 2.0}) {
    const TopoDS_Shape cylinder =
        cylinderWithCircles([turns](const TopoDS_Edge& edge, const Handle(Geom_Curve)& curve, double first, double) {
          BRep_Builder().Range(edge, first, first + turns * curve->Period(), true);
        });
    EXPECT_EQ(damagedGeometry(cylinder).empty(), turns < 1.01) << turns << " turns: " << damagedGeometry(cylinder);
  }
}

// A half cylinder's top edge on [0.1, 3.4e13] (a digit turned into a space) along a half
// circle, a trimmed circle, which is not periodic itself: BRepMesh's model of it took 6 GB
// in 10 s. A trimmed circle counts as its circle: a whole cylinder's circles trimmed to a
// half, their edges' ranges kept or doubled, load once round and not twice.
TEST(CurveOnFace, AnEdgeThatGoesRoundATrimmedCircleIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("oom_edge_round_trimmed_circle.brep")),
            "edge 4 goes 5.44e+12 times round its curve (an edge goes round once at most)");
  for (const double turns : {1.0, 2.0}) {
    const TopoDS_Shape cylinder =
        cylinderWithCircles([turns](const TopoDS_Edge& edge, const Handle(Geom_Curve)& curve, double first, double) {
          const Handle(Geom_Curve) half = new Geom_TrimmedCurve(curve, first, first + M_PI);
          BRep_Builder().UpdateEdge(edge, half, 1e-7);
          BRep_Builder().Range(edge, first, first + turns * 2 * M_PI, true);
        });
    EXPECT_EQ(damagedGeometry(cylinder).empty(), turns == 1.0) << turns << " turns: " << damagedGeometry(cylinder);
  }
}

// The same half cylinder's top edge on [0, 1.4e13] along its circle on the plane top face
// (its 3D curve is sound): BRepCheck's wire self-intersection never ended. Curves stored on
// faces count too: a whole cylinder's circles on its plane faces, their ranges kept or
// doubled there, load once round and not twice.
TEST(CurveOnFace, AnEdgeThatGoesRoundItsCurveOnAFaceIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("timeout_edge_round_its_circle_on_a_plane.brep")),
            "edge 4 goes 2.25e+12 times round its curve on face 4 (an edge goes round once at most)");
  for (const double turns : {1.0, 2.0}) {
    const TopoDS_Shape cylinder = BRepBuilderAPI_Copy(BRepPrimAPI_MakeCylinder(50, 400).Shape()).Shape();
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(cylinder, TopAbs_FACE, faces);
    const TopoDS_Face& bottom = TopoDS::Face(faces(3));  // a plane
    for (TopExp_Explorer e(bottom, TopAbs_EDGE); e.More(); e.Next()) {
      double first = 0, last = 0;
      BRep_Tool::CurveOnSurface(TopoDS::Edge(e.Current()), bottom, first, last);
      BRep_Builder().Range(TopoDS::Edge(e.Current()), bottom, first, first + turns * 2 * M_PI);
    }
    EXPECT_EQ(damagedGeometry(cylinder),
              turns == 1.0 ? "" : "edge 3 goes 2 times round its curve on face 3 (an edge goes round once at most)");
  }
}

// A torus whose vertex record was lost to a stray byte, its seam circle made a parabola:
// the crossing search's copy of the part made the edge without ends [-2e100, 2e100], and
// BRepMesh tessellated it for good. An edge built without vertices is named; with them, not.
TEST(CurveOnFace, AnEdgeWithoutItsVerticesIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("timeout_edge_without_vertices.brep")),
            "edge 1 has no vertex at one end or both");
  TopoDS_Edge bare;
  BRep_Builder().MakeEdge(bare, new Geom_Line(gp::Origin(), gp::DX()), 1e-7);
  EXPECT_EQ(damagedGeometry(bare), "edge 1 has no vertex at one end or both");
  EXPECT_EQ(damagedGeometry(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(10, 0, 0)).Edge()), "");
}

// A cone's semi-angle with its sign flipped (and its radius a digit longer): the apex edge
// lies on a circle of 88 mm, and BRepMesh's edge tessellation never ended on it.
TEST(CurveOnFace, ADegenerateEdgeThatIsNoPointIsNamed) {
  EXPECT_EQ(damagedGeometry(readSeed("timeout_false_degenerate_apex.brep")),
            "edge 1 is marked degenerate yet spans 176 (the part's size 22.7) on face 1");
  EXPECT_EQ(damagedGeometry(readSeed("cone_tip.brep")), "");  // the file it was made from
  // The apex's curve at v = 21 for 21.54 (a lost digit): a circle of 0.4 mm, which the
  // edge's tolerance, read as 1 mm, used to cover; BRepMesh's split of it never ended.
  // The same 176 mm apex circle, with a vertex 196 m off stretching the part's size: the
  // face's own edges give the size.
  EXPECT_EQ(damagedGeometry(readSeed("timeout_false_degenerate_far_vertex.brep")),
            "edge 1 is marked degenerate yet spans 176 (the part's size 22.7) on face 1");
  EXPECT_EQ(damagedGeometry(readSeed("timeout_false_degenerate_within_tolerance.brep")),
            "edge 1 is marked degenerate yet spans 0.402 (the part's size 21.5) on face 1");
}

}  // namespace
}  // namespace hg::geometry
