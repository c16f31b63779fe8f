#pragma once
// The curves of a shape's edges on its faces (pcurves), looked at for the parameter ranges
// that OCCT's own algorithms do not survive. Damaged files carry them (found by fuzz_brep);
// no CAD system writes them.
#include <Geom2d_Curve.hxx>
#include <Geom_Surface.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <functional>
#include <string>
#include <vector>

namespace hg::geometry {

// One edge's curve on one face, and its range.
struct CurveOnFace {
  TopoDS_Edge edge;
  TopoDS_Face face;
  Handle(Geom2d_Curve) curve;  // never null here: edges without one are skipped (ShapeFix makes one)
  double first = 0, last = 0;

  bool emptyRange() const;
  // Where the curve runs away from its surface's parameters, in words, or "": more than
  // kMaxPeriods times round a periodic direction, or more than kMaxPeriods spans beyond a
  // bounded one (a sphere's latitude). OCCT brings a parameter into the period one period at
  // a time (classification, bounds), and meshes the curve's whole range: beyond 2^53 periods
  // the one never ends, and the other takes as long; a thousand is more than any real face
  // winds. An unbounded direction (a cylinder's or cone's length) must stay within
  // `partReach` of the surface's location (a cone's seam at v = -4.4e98 had BRepMesh lay a
  // grid of nodes down its whole length until memory ran out).
  std::string runaway(double partReach) const;
  // Where a degenerate edge (a cone's apex, a sphere's pole) is not a point on this face,
  // in words, or "": its curve on the face maps to points more than kMaxDegenerateSpread of
  // `partSize` (or of the span of the face's other edges, if smaller) apart, whatever the
  // edge's tolerance (a cone's flipped angle put its "apex"
  // on a circle of 88 mm, a lost digit on one of 0.4 mm on a 21 mm cone whose edge claimed a
  // 1 mm tolerance; on each BRepMesh's edge tessellation never ended).
  std::string falseDegenerate(double partSize) const;
  // Where a seam (an edge with two curves on this face, one each side of a periodic
  // surface's cut) has its two curves on the same line, in words, or "": the face's
  // parameters then have no cut, and BRepMesh's preprocessing inserted points on the edge
  // until memory ran out (fuzz_brep: a cone's seam written "2 2" for "2 3", 8 GB in 55 s).
  std::string seamOnItself() const;
};
inline constexpr double kMaxPeriods = 1000;
inline constexpr double kMaxDegenerateSpread = 0.01;
// How many times an edge may go round its periodic 3D curve (a circle, an ellipse, a
// periodic B-spline). Once is a closed edge; more overlaps itself, which no valid solid
// has: every edge of the corpus and of the external STEP and BREP files turns at most
// 1.000000000000 times. BRepMesh's time grows with the turns (a cylinder's top edge:
// 25 turns 1.8 s, 63 turns 10.7 s, 98 turns never ended, found by fuzz_brep); the slack is
// for writers' round-off.
inline constexpr double kMaxEdgeTurns = 1.01;

// How far an edge's curve on a face strays from its 3D curve at most (OCCT's
// BRepLib_ValidateEdge, what BRepCheck compares with the edge's tolerance), in shape units;
// infinite if OCCT cannot tell.
double curveOnFaceDeviation(const TopoDS_Edge& edge, const TopoDS_Face& face);

// A face whose edges lie off it: an edge's curve on the face strays from its 3D curve by
// `distance`. 1-based indices in TopExp::MapShapes order of the shape.
struct FaceOffItsEdges {
  int face = 0, edge = 0;
  double distance = 0;
};
// The curved faces with an edge straying more than `limit` from them, each once (its worst
// edge). Planes are left out: filling one from its edges is what meshing it does, and a
// plane's edges stray where a FreeCAD part's outline crosses itself (5 mm on a 5 mm prism).
std::vector<FaceOffItsEdges> curvedFacesOffTheirEdges(const TopoDS_Shape& shape, double limit);
// A damaged part's curved faces whose edges stray from them by more than this share of its
// size are not meshed by BRepMesh: the mesh fills them from their edges (tessellation.cpp),
// and the load says so (part_check.cpp). ShapeFix heals strays up to 1e-4 of the size;
// beyond a hundred times that, the face is not what its edges say, and BRepMesh at a fine
// deflection ran for minutes on such faces (a cone whose bottom circle ran diagonally
// across it, 54% of the part's size off; a loft's side whose edge had a pole 4 km off).
inline constexpr double kMaxEdgeStray = 0.01;

// The first of the shape's curves on faces for which `why` says something, as "edge 3 <why>
// on face 1"; "" if none. OCCT failing to evaluate one is itself an answer ("cannot be
// evaluated").
std::string firstCurveOnFace(const TopoDS_Shape& shape, const std::function<std::string(const CurveOnFace&)>& why);

// Why OCCT's algorithms cannot be run on this shape at all, or "": an edge without a vertex
// at an end (OCCT takes it as unbounded), weights of a rational
// curve or surface too far apart to compute with (rational_weights.hpp), a degenerate edge that
// is not a point (CurveOnFace::falseDegenerate, against the span of the part's vertices),
// a seam whose two curves on a face coincide (CurveOnFace::seamOnItself),
// an edge that is not degenerate yet has no 3D curve (BRepCheck's No3DCurve: BRepMesh tessellates it through a
// curve on a face and, on a damaged one, did not end), an edge that goes round its 3D
// curve or a curve stored on a face more than kMaxEdgeTurns times (a circle on [4.7,
// 6.9e16], or 98 times round: meshing it never ended; a trimmed circle counts as its circle;
// a circle on a plane 2e12 times round: BRepCheck never ended), or whose
// curve on a face runs away (CurveOnFace::runaway). The loader refuses such a part: no back
// end can be built from it (ShapeFix's rebuilt 3D curve of a damaged edge ran to 2e100).
std::string damagedGeometry(const TopoDS_Shape& shape);

}  // namespace hg::geometry
