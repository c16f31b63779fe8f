#pragma once
// The two searches for the closest point of a surface patch (surface_patches.hpp) to x:
//  - newtonInRect: Newton on |S(u, v) - x|^2, projected on a UV rectangle. Within the
//    patch's focal points (one local minimum at most) it finds the foot, or proves by being
//    pushed against the rectangle that the patch holds none: microseconds.
//  - branchAndBound: where x is near the focal points (several local minima may share the
//    patch), an exhaustive search: cells of the rectangle whose lower bound (the box and
//    slab of their corners, grown by the surface's possible bulge) could beat the best
//    distance by more than the accuracy asked are halved and searched with Newton until
//    none can. Tens to thousands of evaluations (where x is near a focal point the
//    distance is nearly flat around the foot, and cells shrink slowly); the budget is
//    bounded, and a search that runs out of it says so. Counted by the caller as a
//    fallback.
// Both are allocation-free and take the surface as an object with
//   d2(u, v, P, Su, Sv, Suu, Svv, Suv) and value(u, v).
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <cmath>

#include "surface_patches.hpp"

namespace hg::geometry::exact {

enum class SearchEnd { Interior, Boundary, Failed };

struct NewtonResult {
  SearchEnd end = SearchEnd::Failed;
  double u = 0, v = 0;  // where the search ended
  SurfaceJet jet;       // the last evaluation, from which (u, v) was reached by one step
  int evaluations = 0;
};

// Minimises |S(u, v) - x|^2 over `rect`, from `start` (already evaluated when
// `evaluated`: then the first step costs no evaluation). Newton on the exact Hessian where
// it is positive definite, Gauss-Newton elsewhere; a step that made the distance grow is
// halved. It ends when a step moves the point by less than `precision`, or by less than
// `quadraticStop` for a full Newton step: the next would then be below `precision`
// (Newton converges quadratically), so it is not evaluated; the foot follows from the
// last jet to second order.
template <class Surface>
NewtonResult newtonInRect(const Surface& surface, const gp_Pnt& x, const UvRect& rect, const SurfaceJet& start,
                          bool evaluated, double precision, double quadraticStop, int maxIterations = 40) noexcept {
  NewtonResult out;
  SurfaceJet cur = start;
  const double maxStepU = 0.5 * rect.du(), maxStepV = 0.5 * rect.dv();
  double u = start.u, v = start.v, uPrev = u, vPrev = v, fPrev = INFINITY, du = 0, dv = 0;
  int pressed = 0;  // consecutive steps that the rectangle stopped
  int halvings = 0;
  auto finish = [&](SearchEnd end, double uu, double vv) {
    out.end = end;
    out.u = uu;
    out.v = vv;
    return out;
  };
  for (int iteration = 0; iteration < maxIterations; ++iteration) {
    if (iteration > 0 || !evaluated) {
      surface.d2(u, v, cur.p, cur.du, cur.dv, cur.duu, cur.dvv, cur.duv);
      cur.u = u;
      cur.v = v;
      ++out.evaluations;
    }
    const gp_Vec r(x, cur.p);
    const double f = r.SquareMagnitude();
    // Overshot: back up half way. Near the minimum f changes by rounding only; such a
    // change is no overshoot.
    if (f > fPrev * (1 + 1e-12) + 1e-300) {
      // A step the rectangle stopped that made things worse: the minimum over the
      // rectangle lies on its border.
      if (pressed > 0) return finish(SearchEnd::Boundary, uPrev, vPrev);
      du *= 0.5;
      dv *= 0.5;
      if (++halvings > 12 || std::abs(du) * cur.du.Magnitude() + std::abs(dv) * cur.dv.Magnitude() < precision)
        return finish(SearchEnd::Interior, uPrev, vPrev);
      u = std::clamp(uPrev + du, rect.u0, rect.u1);
      v = std::clamp(vPrev + dv, rect.v0, rect.v1);
      continue;
    }
    out.jet = cur;
    const double gu = r.Dot(cur.du), gv = r.Dot(cur.dv);
    const double guu = cur.du.Dot(cur.du), gvv = cur.dv.Dot(cur.dv), guv = cur.du.Dot(cur.dv);
    double a = guu + r.Dot(cur.duu), b = guv + r.Dot(cur.duv), c = gvv + r.Dot(cur.dvv);
    double det = a * c - b * b;
    const bool newtonStep = a > 0 && det > 1e-14 * guu * gvv;
    if (!newtonStep) {  // not locally convex: Gauss-Newton
      a = guu * (1 + 1e-9);
      b = guv;
      c = gvv * (1 + 1e-9);
      det = a * c - b * b;
      if (!(det > 0)) return finish(SearchEnd::Failed, u, v);  // a pole: no direction to go
    }
    du = std::clamp(-(c * gu - b * gv) / det, -maxStepU, maxStepU);
    dv = std::clamp(-(a * gv - b * gu) / det, -maxStepV, maxStepV);
    if (!std::isfinite(du) || !std::isfinite(dv)) return finish(SearchEnd::Failed, u, v);
    uPrev = u;
    vPrev = v;
    fPrev = f;
    const double un = std::clamp(u + du, rect.u0, rect.u1), vn = std::clamp(v + dv, rect.v0, rect.v1);
    // Pushed against the rectangle twice in a row: the minimum over it is on its border.
    const bool stopped = un != u + du || vn != v + dv;
    pressed = stopped ? pressed + 1 : 0;
    const double moved = std::abs(un - u) * std::sqrt(guu) + std::abs(vn - v) * std::sqrt(gvv);
    u = un;
    v = vn;
    if (pressed >= 2) return finish(SearchEnd::Boundary, u, v);
    if (moved < precision) return finish(pressed > 0 ? SearchEnd::Boundary : SearchEnd::Interior, u, v);
    if (moved < quadraticStop && pressed == 0 && newtonStep) return finish(SearchEnd::Interior, u, v);
  }
  return finish(SearchEnd::Failed, u, v);
}

// The branch and bound's next cell: the one with the lowest bound, taken out of the first
// `count` (few: a linear scan beats a heap here, and needs no allocation).
template <class Cell>
Cell popLowest(Cell* cells, int& count) noexcept {
  int k = 0;
  for (int i = 1; i < count; ++i)
    if (cells[i].lower < cells[k].lower) k = i;
  const Cell cell = cells[k];
  cells[k] = cells[--count];
  return cell;
}

// Where no cell could hide a closer foot (`certain`), or the budget ran out first.
struct BranchResult {
  bool found = false;    // a foot closer than the bound, accepted by the caller
  double u = 0, v = 0, distance = 0;
  bool certain = true;   // false: cells that might still hold a closer foot were left
};

// A lower bound of the distance from x to the surface over a cell: the box and the slab
// (along the patch's axis) of its four corners, grown by how far the surface can bulge
// between them (the bilinear interpolation error, from the patch's second derivative
// bounds). Second order in the cell's size, so cells shrink fast to what they hold.
template <class Surface>
double cellLowerBound(const Surface& surface, const gp_Pnt& x, const SurfacePatch& patch, const UvRect& r) noexcept {
  const gp_Pnt corners[4] = {surface.value(r.u0, r.v0), surface.value(r.u1, r.v0), surface.value(r.u0, r.v1),
                             surface.value(r.u1, r.v1)};
  const double du = r.du(), dv = r.dv();
  const double sag = (du * du * patch.maxSuu + 2 * du * dv * patch.maxSuv + dv * dv * patch.maxSvv) / 8;
  // The box, and the slab along the patch's normal.
  Aabb box;
  double lo = INFINITY, hi = -INFINITY;
  const Vec3 axis = patch.bound.oriented() ? Vec3(patch.bound.axes.col(2)) : Vec3::Zero();
  for (const gp_Pnt& c : corners) {
    const Vec3 p(c.X(), c.Y(), c.Z());
    box.extend(p);
    const double h = axis.dot(p);
    lo = std::min(lo, h);
    hi = std::max(hi, h);
  }
  const Vec3 xv(x.X(), x.Y(), x.Z());
  const double d2 = box.inflated(sag).squaredDistance(xv);
  const double h = axis.dot(xv);
  const double slab = h < lo - sag ? lo - sag - h : h > hi + sag ? h - hi - sag : 0.0;
  return std::sqrt(std::max(d2, slab * slab));
}

// Searches `patch` exhaustively for a foot closer than `bound` that `accept(u, v)`
// accepts (inside the trimmed face): cells that could beat the bound by more than
// `accuracy` are halved, and searched by Newton from their centre when that centre
// already beats it. `outside(rect)` says whether a cell lies wholly outside the face.
template <class Surface, class Accept, class Outside>
BranchResult branchAndBound(const Surface& surface, const gp_Pnt& x, const SurfacePatch& patch, double bound,
                            Accept&& accept, Outside&& outside, double accuracy, double precision,
                            int& budget) noexcept {
  struct Cell {
    UvRect rect;
    double lower;  // no point of the cell is closer than this
  };
  // Bounded by the caller's budget of surface evaluations, as the servo thread may run
  // this: a query's whole budget is about 0.1-0.5 ms (cubic to degree-14 rational).
  constexpr int kCapacity = 128;
  Cell cells[kCapacity];
  int count = 0, evaluations = 0;
  BranchResult result;
  auto push = [&](const UvRect& r) {
    if (outside(r)) return;
    const double lower = cellLowerBound(surface, x, patch, r);
    evaluations += 4;
    if (lower >= bound - accuracy) return;
    if (count == kCapacity) {
      result.certain = false;
      return;
    }
    cells[count++] = {r, lower};
  };
  push(patch.rect);
  while (count > 0 && evaluations < budget) {
    const Cell cell = popLowest(cells, count);
    if (cell.lower >= bound - accuracy) continue;
    const UvRect& r = cell.rect;
    double u = 0.5 * (r.u0 + r.u1), v = 0.5 * (r.v0 + r.v1);
    ++evaluations;
    if (surface.value(u, v).Distance(x) < bound) {
      // The centre already beats the bound: Newton from it, within the cell and a margin.
      const UvRect around{std::max(patch.rect.u0, r.u0 - 0.5 * r.du()), std::min(patch.rect.u1, r.u1 + 0.5 * r.du()),
                          std::max(patch.rect.v0, r.v0 - 0.5 * r.dv()), std::min(patch.rect.v1, r.v1 + 0.5 * r.dv())};
      SurfaceJet from;
      from.u = u;
      from.v = v;
      const NewtonResult n = newtonInRect(surface, x, around, from, false, precision, 0, 12);
      evaluations += n.evaluations;
      if (n.end == SearchEnd::Interior) {
        u = n.u;
        v = n.v;
        const double d = surface.value(u, v).Distance(x);
        // The patch's own closest point (the ball of radius d about x touches it and the
        // patch bends less): nothing else on it can be closer.
        const bool global = patch.minimumIsGlobal(Vec3(x.X(), x.Y(), x.Z()), d);
        if (d < bound && accept(u, v)) {
          bound = d;
          result = {true, u, v, d, result.certain};
        }
        if (global) {
          budget -= evaluations;
          return result;
        }
      }
    }
    // Halve across the longer side (in space).
    if (patch.lipschitzU * r.du() >= patch.lipschitzV * r.dv()) {
      const double m = 0.5 * (r.u0 + r.u1);
      push({r.u0, m, r.v0, r.v1});
      push({m, r.u1, r.v0, r.v1});
    } else {
      const double m = 0.5 * (r.v0 + r.v1);
      push({r.u0, r.u1, r.v0, m});
      push({r.u0, r.u1, m, r.v1});
    }
  }
  for (int i = 0; i < count; ++i)
    if (cells[i].lower < bound - accuracy) result.certain = false;
  budget -= evaluations;
  return result;
}

}  // namespace hg::geometry::exact
