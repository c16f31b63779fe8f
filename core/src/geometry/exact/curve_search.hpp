#pragma once
// The searches for the closest point of a curve piece (curve_pieces.hpp) to x: Newton on
// an interval (clear of the piece's focal points: the foot, or the proof that the piece
// holds none), and the exhaustive branch and bound elsewhere. The curve's counterpart of
// patch_search.hpp; the curve is a callable c2(t, P, C', C'').
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <cmath>

#include "curve_pieces.hpp"
#include "patch_search.hpp"  // SearchEnd

namespace hg::geometry::exact {

// Minimises |C(t) - x|^2 over [a, b] from t (left where the search ended).
template <class C2>
SearchEnd newtonOnInterval(const C2& c2, const gp_Pnt& x, double a, double b, double& t, double tolerance,
                           int maxIterations = 40, int* evaluations = nullptr) noexcept {
  gp_Pnt c;
  gp_Vec d1, d2;
  const double maxStep = 0.5 * (b - a);
  double tPrev = t, fPrev = INFINITY, dt = 0;
  int pressed = 0;
  for (int iteration = 0; iteration < maxIterations; ++iteration) {
    c2(t, c, d1, d2);
    if (evaluations) ++*evaluations;
    const gp_Vec r(x, c);
    const double f = r.SquareMagnitude();
    if (f > fPrev * (1 + 1e-12) + 1e-300) {  // overshot: back up half way
      dt *= 0.5;
      if (std::abs(dt) * d1.Magnitude() < 1e-3 * tolerance) {
        t = tPrev;
        return pressed > 0 ? SearchEnd::Boundary : SearchEnd::Interior;
      }
      t = std::clamp(tPrev + dt, a, b);
      continue;
    }
    const double g = r.Dot(d1), speed2 = d1.Dot(d1);
    double h = speed2 + r.Dot(d2);
    if (!(h > 0)) h = speed2;  // not locally convex: Gauss-Newton
    dt = std::clamp(-g / h, -maxStep, maxStep);
    if (!std::isfinite(dt)) return SearchEnd::Failed;
    tPrev = t;
    fPrev = f;
    const double next = std::clamp(t + dt, a, b);
    pressed = next != t + dt ? pressed + 1 : 0;
    const double moved = std::abs(next - t) * std::sqrt(speed2);
    t = next;
    if (pressed >= 2) return SearchEnd::Boundary;
    if (moved < 1e-3 * tolerance) return pressed > 0 ? SearchEnd::Boundary : SearchEnd::Interior;
  }
  return SearchEnd::Failed;
}

struct CurveBranchResult {
  bool found = false;
  double t = 0, distance = 0;
  bool certain = true;
};

// Searches the piece exhaustively for a foot closer than `bound` that accept(t) accepts:
// cells whose lower bound (the distance to their chord, less how far the curve can bulge
// from it) could beat the bound by more than `accuracy` are halved, and searched by
// Newton from their middle when that already beats it.
template <class C2, class Accept>
CurveBranchResult branchAndBound1D(const C2& c2, const gp_Pnt& x, const CurvePiece& piece, double bound,
                                   Accept&& accept, double accuracy, double tolerance, int& budget) noexcept {
  struct Cell {
    double a, b, lower;
    gp_Pnt pa, pb;  // the curve at a and b
  };
  constexpr int kCapacity = 64;  // and the caller's budget of evaluations, as for surfaces
  Cell cells[kCapacity];
  int count = 0, evaluations = 0;
  CurveBranchResult result;
  auto pointAt = [&](double t) {
    gp_Pnt p;
    gp_Vec d1, d2;
    c2(t, p, d1, d2);
    ++evaluations;
    return p;
  };
  auto push = [&](double a, double b, const gp_Pnt& pa, const gp_Pnt& pb) {
    // Distance from x to the chord, less the bulge h^2 max|C''| / 8.
    const gp_Vec chord(pa, pb), toX(pa, x);
    const double len2 = chord.SquareMagnitude();
    const double s = len2 > 0 ? std::clamp(toX.Dot(chord) / len2, 0.0, 1.0) : 0.0;
    const double lower = pa.Translated(chord * s).Distance(x) - (b - a) * (b - a) * piece.maxD2 / 8;
    if (lower >= bound - accuracy) return;
    if (count == kCapacity) {
      result.certain = false;
      return;
    }
    cells[count++] = {a, b, lower, pa, pb};
  };
  push(piece.t0, piece.t1, pointAt(piece.t0), pointAt(piece.t1));
  while (count > 0 && evaluations < budget) {
    const Cell cell = popLowest(cells, count);
    if (cell.lower >= bound - accuracy) continue;
    const double w = cell.b - cell.a, m = 0.5 * (cell.a + cell.b);
    const gp_Pnt pm = pointAt(m);
    if (pm.Distance(x) < bound) {
      // The middle already beats the bound: Newton from it, within the cell and a margin.
      double t = m;
      if (newtonOnInterval(c2, x, std::max(piece.t0, cell.a - 0.5 * w), std::min(piece.t1, cell.b + 0.5 * w), t,
                           tolerance, 12, &evaluations) == SearchEnd::Interior) {
        const double d = pointAt(t).Distance(x);
        if (d < bound && accept(t)) {
          bound = d;
          result = {true, t, d, result.certain};
        }
      }
    }
    push(cell.a, m, cell.pa, pm);
    push(m, cell.b, pm, cell.pb);
  }
  for (int i = 0; i < count; ++i)
    if (cells[i].lower < bound - accuracy) result.certain = false;
  budget -= evaluations;
  return result;
}

}  // namespace hg::geometry::exact
