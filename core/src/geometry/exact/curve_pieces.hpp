#pragma once
// A freeform edge curve (ellipse, hyperbola, parabola, B-spline, Bézier, offset, ...) cut,
// once, into pieces along which its tangent turns by less than a set angle: the curve's
// counterpart of surface_patches.hpp. Each piece carries a bound for the part's BVH, its
// curvature and size (which tell whether x is clear of its focal points for every foot that
// could matter: then the piece holds one local minimum at most, which Newton finds), a
// Lipschitz bound for the exhaustive search, and five start points.
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

#include <functional>
#include <vector>

#include "feature_bvh.hpp"

namespace hg::geometry::exact {

struct CurvePiece {
  static constexpr int kSeeds = 5;
  double t0 = 0, t1 = 0;
  LeafBound bound;        // model units
  double lipschitz = 0;   // bound of |C'| on the piece
  double maxD2 = 0;       // bound of |C''| on the piece
  double kappa = 0;       // bound of the curvature on the piece
  double spread = 0;      // every point of the piece lies within this of the bound's centre
  double seedT[kSeeds] = {};
  gp_Pnt seedP[kSeeds];

  // Whether a Newton search that ended inside the piece, at distance d from x, found its
  // closest point: a curve bending less than the circle of radius d about x (d k < 1)
  // stays outside that circle's ball along so short a piece.
  bool minimumIsGlobal(double d) const noexcept { return d * kappa < 0.9; }
  // Whether a Newton search pushed out of the piece proves it holds no foot closer than
  // `best`: the distance's second derivative along the curve, 1 - (x - C).K per unit arc
  // length, is positive wherever |x - C| k < 1; two minima would need a maximum between
  // them, at most best + spread from x (the distance grows no faster than the arc).
  bool clearOfFocus(double best) const noexcept { return (best + spread) * kappa < 0.9; }
};

using CurveD2 = std::function<void(double t, gp_Pnt& p, gp_Vec& d1, gp_Vec& d2)>;

struct PieceOptions {
  double maxTurn_rad = 0.3;
  double maxSpreadCurvature = 0.2;  // a piece's half length is at most this over its curvature
  int maxPieces = 1024;  // per edge
  int maxDepth = 16;
  double tolerance = 0;  // model units, added to every bound
};

// Cuts [t0, t1] at the breaks (knots), then halves every piece whose tangent turns too much.
std::vector<CurvePiece> buildCurvePieces(const CurveD2& curve, double t0, double t1, const std::vector<double>& breaks,
                                         const PieceOptions& options);

}  // namespace hg::geometry::exact
