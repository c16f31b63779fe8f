// The two searches on a patch: Newton finds the foot (or is pushed out of a patch that
// holds none), and the exhaustive search finds the closest of several local minima.
#include <gtest/gtest.h>

#include <random>

#include "geometry/exact/face_model.hpp"
#include "geometry/exact/patch_search.hpp"
#include "surface_fixtures.hpp"

namespace hg::geometry::exact {
namespace {

// The closest point of the surface over a rectangle, by a grid and pattern search. A patch
// holds less than one wave of the fixtures' surfaces, so a 60 x 60 grid lands in the global
// minimum's basin; the pattern search then refines it until its step is below the parameter's
// resolution (at most 200 steps). A 200 x 200 grid cost 11 times as much: 154 s for the sweep
// below in Release.
double bruteForce(const FaceModel& s, const gp_Pnt& x, const UvRect& r, double& bu, double& bv) {
  double best = INFINITY;
  const int n = 60;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double u = r.u0 + r.du() * i / n, v = r.v0 + r.dv() * j / n;
      if (const double d = s.value(u, v).Distance(x); d < best) best = d, bu = u, bv = v;
    }
  double hu = r.du() / n, hv = r.dv() / n;
  for (int k = 0; k < 200 && bu + hu != bu; ++k) {
    bool moved = false;
    for (const auto& [du, dv] : {std::pair{hu, 0.0}, {-hu, 0.0}, {0.0, hv}, {0.0, -hv}}) {
      const double u = std::clamp(bu + du, r.u0, r.u1), v = std::clamp(bv + dv, r.v0, r.v1);
      if (const double d = s.value(u, v).Distance(x); d < best) best = d, bu = u, bv = v, moved = true;
    }
    if (!moved) hu *= 0.5, hv *= 0.5;
  }
  return best;
}

const FaceModel& wavy() {
  static const TopoDS_Face face = test::wavyFace();
  static const FaceModel model(face, 80.0);
  return model;
}

TEST(PatchSearch, NewtonFindsTheFootOfNearPoints) {
  const FaceModel& s = wavy();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> lateral(-25, 25), height(-2, 2);
  int interior = 0;
  const int points = 100;
  for (int k = 0; k < points; ++k) {
    const double px = lateral(rng), py = lateral(rng) * 0.8;
    const gp_Pnt x(px, py, 6 * std::sin(px / 8) * std::cos(py / 10) + height(rng));
    for (const SurfacePatch& p : s.patches()) {
      double bu, bv;
      const double truth = bruteForce(s, x, p.rect, bu, bv);
      const bool footInside = bu > p.rect.u0 + 1e-6 * p.rect.du() && bu < p.rect.u1 - 1e-6 * p.rect.du() &&
                              bv > p.rect.v0 + 1e-6 * p.rect.dv() && bv < p.rect.v1 - 1e-6 * p.rect.dv();
      if (!footInside || !p.clearOfFocus(Vec3(x.X(), x.Y(), x.Z()), truth)) continue;
      const NewtonResult n = newtonInRect(s, x, p.rect, p.seeds[0], true, 1e-9, 1e-4);
      ASSERT_EQ(n.end, SearchEnd::Interior);
      EXPECT_NEAR(s.value(n.u, n.v).Distance(x), truth, 1e-9);
      ++interior;
    }
  }
  EXPECT_GT(interior, 80 * points / 100);
}

TEST(PatchSearch, NewtonIsPushedOutOfAPatchWithoutFoot) {
  const FaceModel& s = wavy();
  const SurfacePatch& p = s.patches().front();
  // Far beyond the patch's corner, over the rest of the surface.
  const gp_Pnt x(20, 15, 3);
  double bu, bv;
  bruteForce(s, x, p.rect, bu, bv);
  ASSERT_TRUE(bu == p.rect.u0 || bu == p.rect.u1 || bv == p.rect.v0 || bv == p.rect.v1);
  EXPECT_EQ(newtonInRect(s, x, p.rect, p.seeds[0], true, 1e-9, 1e-4).end, SearchEnd::Boundary);
}

// One patch spanning both dips of the sheet, seen from below: Newton from the middle may
// slide into either dip; the exhaustive search finds the deeper one.
TEST(PatchSearch, ExhaustiveSearchFindsTheCloserOfTwoMinima) {
  const TopoDS_Face face = test::twoDipsFace();
  const FaceModel s(face, 50.0);
  SurfacePatch whole = s.patches().front();
  double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
  for (const SurfacePatch& p : s.patches()) {
    u0 = std::min(u0, p.rect.u0), u1 = std::max(u1, p.rect.u1), v0 = std::min(v0, p.rect.v0), v1 = std::max(v1, p.rect.v1);
    whole.lipschitzU = std::max(whole.lipschitzU, p.lipschitzU), whole.lipschitzV = std::max(whole.lipschitzV, p.lipschitzV);
    whole.maxSuu = std::max(whole.maxSuu, p.maxSuu), whole.maxSuv = std::max(whole.maxSuv, p.maxSuv);
    whole.maxSvv = std::max(whole.maxSvv, p.maxSvv);
    whole.kTowards = std::max(whole.kTowards, p.kTowards), whole.kAway = std::max(whole.kAway, p.kAway);
  }
  whole.rect = {u0, u1, v0, v1};
  whole.bound.half = Vec3::Constant(-1);  // no slab: the sheet with its dips is not flat
  for (const double below : {15.0, 25.0}) {
    const gp_Pnt x(-0.5, 0.3, -below);
    double bu, bv;
    const double truth = bruteForce(s, x, whole.rect, bu, bv);
    ASSERT_LT(s.value(bu, bv).X(), 0);  // the left dip is the closer
    int budget = 5000;
    const BranchResult r = branchAndBound(
        s, x, whole, INFINITY, [](double, double) { return true; }, [](const UvRect&) { return false; }, 1e-7, 1e-9,
        budget);
    ASSERT_TRUE(r.found);
    EXPECT_NEAR(r.distance, truth, 1e-7);
    EXPECT_LT(s.value(r.u, r.v).X(), 0);
  }
}

// Where it cannot be sure within its budget (x at a dip's centre of curvature, where the
// distance is flat to second order around the foot), it says so.
TEST(PatchSearch, ExhaustiveSearchSaysWhenItIsNotSure) {
  const FaceModel& s = wavy();
  int unsure = 0;
  for (const SurfacePatch& p : s.patches()) {
    const double k = std::max(p.kTowards, p.kAway);
    if (k < 0.08) continue;
    const Vec3 c = p.bound.centre + p.bound.axes.col(2) / (p.kTowards > p.kAway ? k : -k);
    int budget = 600;
    const BranchResult r = branchAndBound(
        s, gp_Pnt(c.x(), c.y(), c.z()), p, INFINITY, [](double, double) { return true; },
        [](const UvRect&) { return false; }, 1e-7, 1e-9, budget);
    unsure += !r.certain;
  }
  EXPECT_GT(unsure, 0);
}

}  // namespace
}  // namespace hg::geometry::exact
