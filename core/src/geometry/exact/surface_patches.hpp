#pragma once
// A freeform face cut, once, into nearly flat patches: rectangles of its UV box on which
// the surface turns by less than a set angle. Each patch carries what makes a query on it
// both fast and certain:
//  - a bound (an oriented box over its mean normal), so that the part's BVH visits only
//    the patches that can hold a closer point than the best found so far;
//  - its curvature and size, which tell whether x is clear of the patch's focal points (the
//    centres of curvature, P + N / k) for every foot that could matter: then the patch
//    holds one local minimum of the distance at most, so a Newton search that ends inside
//    the patch has found its foot and one pushed out of it proves there is none inside.
//    Where it is not, a slower exhaustive search (branch and bound) answers;
//  - bounds of the surface's derivatives for that search, and five start points.
// Bounds and curvature come from samples, with safety margins: the cut is fine enough that
// a surface of bounded curvature cannot escape them between samples.
#include <gp_Pnt.hxx>

#include <functional>
#include <vector>

#include "feature_bvh.hpp"
#include "surface_jet.hpp"

namespace hg::geometry::exact {

struct UvRect {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  double du() const { return u1 - u0; }
  double dv() const { return v1 - v0; }
};


struct SurfacePatch {
  UvRect rect;
  LeafBound bound;            // model units
  // The largest principal curvature bending towards +N (S_u x S_v) and towards -N.
  double kTowards = 0, kAway = 0;
  double spread = 0;  // every point of the patch lies within this of the bound's centre
  double lipschitzU = 0, lipschitzV = 0;  // bounds of |S_u|, |S_v| on the patch
  double maxSuu = 0, maxSuv = 0, maxSvv = 0;  // bounds of the second derivatives
  // Start points: the centre and the middles of the four quarters. A first Newton step
  // from a seed costs no evaluation.
  static constexpr int kSeeds = 5;
  SurfaceJet seeds[kSeeds];

  // Whether a Newton search on the patch that ended inside it, at a point of the surface
  // at distance d from x, found the patch's closest point. The ball of radius d about x
  // touches the surface there; a surface bending towards x less than that ball (d k < 1,
  // k the curvature towards x's side) stays outside it all over so nearly flat a patch.
  bool minimumIsGlobal(const Vec3& x, double d) const noexcept { return d * curvatureTowards(x) < kFocalMargin; }
  // Whether a Newton search on the patch that was pushed out of it proves the patch holds
  // no foot closer than `best`. At a critical point P (x - P along N, at distance d) the
  // distance's Hessian is I - d II: a strict local minimum while d k < 1. A minimum in the
  // patch would have been found unless a saddle or maximum separated it from the start,
  // and the distance grows by no more than the path between them: such a point lies at
  // most best + spread from x. If that is short of the focal distance 1/k, there is none.
  bool clearOfFocus(const Vec3& x, double best) const noexcept {
    return (best + spread) * curvatureTowards(x) < kFocalMargin;
  }
  // The largest curvature bending towards x's side of the patch (both sides', when x lies
  // within its thickness). The side is the searched surface's: an offset face's patch
  // bounds the offset surface but is searched, and bends, on its basis.
  double curvatureTowards(const Vec3& x) const noexcept {
    if (!bound.oriented()) return std::max(kTowards, kAway);
    const double h = bound.axes.col(2).dot(x - searchedCentre);
    return h > searchedHalfThickness ? kTowards : h < -searchedHalfThickness ? kAway : std::max(kTowards, kAway);
  }
  Vec3 searchedCentre = Vec3::Zero();  // the searched surface's oriented box: centre
  double searchedHalfThickness = 0;    // and half thickness along the normal
  double turn = 0;                     // largest angle of a normal from the mean
  static constexpr double kFocalMargin = 0.9;
};

// Evaluates the surface and its first and second derivatives at (u, v) of the face's box.
using SurfaceD2 = std::function<void(double u, double v, gp_Pnt& p, gp_Vec& du, gp_Vec& dv, gp_Vec& duu,
                                     gp_Vec& dvv, gp_Vec& duv)>;

struct PatchOptions {
  double maxTurn_rad = 0.3;   // the normal turns by at most about this on a patch
  double maxSpreadCurvature = 0.2;  // and its radius is at most this over its curvature
  int maxPatches = 16384;     // per face (about 1 KB each)
  int maxDepth = 12;          // halvings of one knot span
  double tolerance = 0;       // model units, added to every bound
};

// Cuts `box` at the given breaks (the surface's knots: the derivatives may jump there),
// then halves every rectangle whose normal turns too much.
std::vector<SurfacePatch> buildSurfacePatches(const SurfaceD2& surface, const UvRect& box,
                                              const std::vector<double>& uBreaks,
                                              const std::vector<double>& vBreaks, const PatchOptions& options);

}  // namespace hg::geometry::exact
