// The pieces of a freeform curve and the searches on them: the pieces tile the range,
// their bounds hold the curve, and Newton and the exhaustive search find the foot.
#include <gtest/gtest.h>

#include <GC_MakeEllipse.hxx>
#include <Geom_Ellipse.hxx>
#include <gp_Elips.hxx>

#include "geometry/exact/curve_pieces.hpp"
#include "geometry/exact/curve_search.hpp"
#include "surface_fixtures.hpp"

namespace hg::geometry::exact {
namespace {

struct Curve {
  Handle(Geom_Curve) c;
  void d2(double t, gp_Pnt& p, gp_Vec& d1, gp_Vec& dd2) const { c->D2(t, p, d1, dd2); }
  void operator()(double t, gp_Pnt& p, gp_Vec& d1, gp_Vec& dd2) const { c->D2(t, p, d1, dd2); }
};

std::vector<CurvePiece> piecesOf(const Curve& curve) {
  return buildCurvePieces([&](double t, gp_Pnt& p, gp_Vec& d1, gp_Vec& d2) { curve.d2(t, p, d1, d2); },
                          curve.c->FirstParameter(), curve.c->LastParameter(), {}, PieceOptions{});
}

double bruteForce(const Curve& curve, const gp_Pnt& x, double t0, double t1) {
  double best = INFINITY, bt = t0;
  for (int i = 0; i <= 20000; ++i) {
    const double t = t0 + (t1 - t0) * i / 20000;
    if (const double d = curve.c->Value(t).Distance(x); d < best) best = d, bt = t;
  }
  double h = (t1 - t0) / 20000;
  for (int k = 0; k < 60; ++k) {
    bool moved = false;
    for (const double dt : {h, -h})
      if (const double d = curve.c->Value(std::clamp(bt + dt, t0, t1)).Distance(x); d < best)
        best = d, bt = std::clamp(bt + dt, t0, t1), moved = true;
    if (!moved) h *= 0.5;
  }
  return best;
}

const Curve kCurves[] = {{test::wavyCurve()}, {new Geom_Ellipse(gp_Elips(gp_Ax2(), 30, 6))}};

TEST(CurvePieces, TileTheRangeAndBoundTheCurve) {
  for (const Curve& curve : kCurves) {
    const auto pieces = piecesOf(curve);
    ASSERT_GT(pieces.size(), 3u);
    EXPECT_DOUBLE_EQ(pieces.front().t0, curve.c->FirstParameter());
    EXPECT_DOUBLE_EQ(pieces.back().t1, curve.c->LastParameter());
    for (std::size_t i = 0; i < pieces.size(); ++i) {
      if (i > 0) {
        EXPECT_DOUBLE_EQ(pieces[i].t0, pieces[i - 1].t1);
      }
      for (int k = 0; k <= 50; ++k) {
        const gp_Pnt q = curve.c->Value(pieces[i].t0 + (pieces[i].t1 - pieces[i].t0) * k / 50);
        EXPECT_EQ(pieces[i].bound.squaredDistance(Vec3(q.X(), q.Y(), q.Z())), 0.0);
      }
      EXPECT_LE(pieces[i].spread * pieces[i].kappa, 1.01 * PieceOptions{}.maxSpreadCurvature);
    }
  }
}

TEST(CurveSearch, NewtonFindsTheFootOnAPieceClearOfFocus) {
  for (const Curve& curve : kCurves) {
    int checked = 0;
    for (const CurvePiece& piece : piecesOf(curve)) {
      // Points a little off the curve at the piece's middle.
      const double tm = 0.5 * (piece.t0 + piece.t1);
      gp_Pnt p;
      gp_Vec d1, d2;
      curve.d2(tm, p, d1, d2);
      for (const double off : {-1.0, 0.5, 1.0}) {
        const gp_Vec side = d1.Crossed(gp_Vec(0, 0, 1)).Normalized() * off;
        const gp_Pnt x = p.Translated(side + gp_Vec(0, 0, 0.3));
        const double truth = bruteForce(curve, x, piece.t0, piece.t1);
        if (!piece.clearOfFocus(truth)) continue;
        double t = piece.seedT[0];
        ASSERT_EQ(newtonOnInterval(curve, x, piece.t0, piece.t1, t, 1e-9), SearchEnd::Interior);
        EXPECT_NEAR(curve.c->Value(t).Distance(x), truth, 1e-9);
        ++checked;
      }
    }
    EXPECT_GT(checked, 10);
  }
}

TEST(CurveSearch, ExhaustiveSearchFindsTheClosestOfSeveralMinima) {
  const Curve& wave = kCurves[0];
  // One piece covering the whole wave, and points from which several crests are near.
  CurvePiece whole;
  whole.t0 = wave.c->FirstParameter();
  whole.t1 = wave.c->LastParameter();
  for (const CurvePiece& p : piecesOf(wave)) {
    whole.lipschitz = std::max(whole.lipschitz, p.lipschitz);
    whole.maxD2 = std::max(whole.maxD2, p.maxD2);
  }
  for (const gp_Pnt& x : {gp_Pnt(0, 0, 5), gp_Pnt(9, -3, 2), gp_Pnt(-20, 12, 0)}) {
    int budget = 400;
    const CurveBranchResult r =
        branchAndBound1D(wave, x, whole, INFINITY, [](double) { return true; }, 1e-8, 1e-10, budget);
    EXPECT_LT(budget, 400);  // it was spent, and said how much
    ASSERT_TRUE(r.found);
    EXPECT_TRUE(r.certain);
    EXPECT_NEAR(r.distance, bruteForce(wave, x, whole.t0, whole.t1), 1e-7);
  }
}

}  // namespace
}  // namespace hg::geometry::exact
