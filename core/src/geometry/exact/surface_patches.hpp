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

  // Whether x is clear of the patch's focal points: at every point P of the patch, the
  // height h = (x - P).N of x over the tangent plane stays below 1/k for the curvature k
  // bending towards x's side. The squared distance's Hessian at P, in orthonormal
  // coordinates of the tangent plane, is I - h II: positive definite all over the patch,
  // which then holds one local minimum of the distance at most, that Newton goes to (or is
  // pushed out of the patch towards). h is bounded by intervals: x - c in the patch's frame
  // against the range of N's components there, plus the range of (c - P).N. Independent of
  // any best distance; tight along straight directions (a long strip of a cylinder).
  bool focalClear(const Vec3& x) const noexcept {
    if (!bound.oriented()) return false;
    const Vec3 a = bound.axes.transpose() * (x - searchedCentre);
    double up = heightHi, down = heightLo;
    for (int i = 0; i < 3; ++i) {
      up += std::max(a[i] * normalLo[i], a[i] * normalHi[i]);
      down += std::min(a[i] * normalLo[i], a[i] * normalHi[i]);
    }
    return (up <= 0 || up * kTowards < kFocalMargin) && (down >= 0 || -down * kAway < kFocalMargin);
  }
  Vec3 normalLo = Vec3::Zero(), normalHi = Vec3::Zero();  // N's components in the frame
  double heightLo = 0, heightHi = 0;                       // the range of (c - P).N

  // Whether a Newton search on the patch that ended inside it, at a point of the surface
  // at distance d from x, found the patch's closest point. The ball of radius d about x
  // touches the surface there; a surface bending towards x less than that ball (d k < 1,
  // k the curvature towards x's side) stays outside it all over so nearly flat a patch.
  bool minimumIsGlobal(const Vec3& x, double d) const noexcept { return d * curvatureTowards(x) < kFocalMargin; }
  // Whether a Newton search on the patch that was pushed out of it proves the patch holds
  // no foot closer than `best`: the distance is unimodal over the patch while every
  // point of it, at most best + spread from x, is short of the focal distance 1/k.
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
  // and its size, along the directions it bends in, is at most this over its curvature
  double maxSpreadCurvature = 0.2;
  double straightTurn_rad = 0.02;  // a direction the normal turns less along is straight
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
