#pragma once
// The weights of a part's rational curves and surfaces (NURBS and rational Bezier): how far
// apart they lie. A rational surface is the poles' average weighted by them; weights far
// apart leave the light poles' share below a double's digits, and BRepMesh's Delaunay
// triangulation of such a face ran out of memory (fuzz_brep: a loft's weights 1 and 1.8e17,
// a pole 88 km off a 160 mm part; 6 GB in 12 s in Release, in BRepMesh_CircleTool's cells).
#include <TopoDS_Shape.hxx>

#include <string>

namespace hg::geometry {

// How many times apart a curve's or surface's largest and smallest weight may lie. Real
// parts' lie at most 3 times apart (the corpus, its external STEP files, the sample parts:
// test_rational_weights); a circle's arc as a NURBS of one span needs 1/cos(angle/2), 10 for
// 169 degrees. Well beyond these, and well below the 1e16 where a double holds nothing of
// the light poles.
inline constexpr double kMaxWeightRatio = 1e8;

// The curve or surface whose weights lie farthest apart, and how far: largest over smallest,
// 1 for a part without weights. A trimmed, offset, extruded or revolved surface or curve is
// judged by what it is made from.
struct WeightSpread {
  double spread = 1;
  std::string where;  // "face 2's surface", "edge 3's curve", "edge 3's curve on face 1"
};
WeightSpread widestWeights(const TopoDS_Shape& shape);

// The widest weights in words if they lie more than kMaxWeightRatio apart ("face 2's surface
// has weights 1.8e+17 times apart"), or "".
std::string weightsTooFarApart(const TopoDS_Shape& shape);

}  // namespace hg::geometry
