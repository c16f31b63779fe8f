// The closed-form feet of elementary surfaces against brute force: the best listed foot is
// the surface's closest point, every listed foot is a local minimum, and on a cone or an
// apple torus the second listed foot is the one a face holding only that part needs.
#include <gtest/gtest.h>

#include <ElSLib.hxx>
#include <gp_Ax3.hxx>

#include <cmath>
#include <functional>
#include <random>

#include "geometry/exact/closed_form_foot.hpp"

namespace hg::geometry::exact {
namespace {

using Surface = std::function<gp_Pnt(double u, double v)>;

// The smallest distance from x to the surface over a fine grid of [u0, u1] x [v0, v1],
// refined around the best grid point.
double bruteForce(const Surface& s, const gp_Pnt& x, double u0, double u1, double v0, double v1) {
  double best = INFINITY, bu = 0, bv = 0;
  const int n = 400;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double u = u0 + (u1 - u0) * i / n, v = v0 + (v1 - v0) * j / n;
      if (const double d = s(u, v).Distance(x); d < best) best = d, bu = u, bv = v;
    }
  double hu = (u1 - u0) / n, hv = (v1 - v0) / n;
  for (int k = 0; k < 60; ++k) {  // pattern search around the grid's best
    bool moved = false;
    for (const auto& [du, dv] : {std::pair{hu, 0.0}, {-hu, 0.0}, {0.0, hv}, {0.0, -hv}})
      if (const double d = s(bu + du, bv + dv).Distance(x); d < best) best = d, bu += du, bv += dv, moved = true;
    if (!moved) hu *= 0.5, hv *= 0.5;
  }
  return best;
}

// No point of the surface near (u, v) is closer than (u, v) itself.
bool isLocalMinimum(const Surface& s, const gp_Pnt& x, double u, double v) {
  const double d = s(u, v).Distance(x);
  for (const double h : {1e-3, 1e-5})
    for (const auto& [du, dv] : {std::pair{h, 0.0}, {-h, 0.0}, {0.0, h}, {0.0, -h}, {h, h}, {-h, -h}, {h, -h}, {-h, h}})
      if (s(u + du, v + dv).Distance(x) < d - 1e-12) return false;
  return true;
}

double bestOf(const SurfaceFeet& feet, const Surface& s, const gp_Pnt& x) {
  double best = INFINITY;
  for (int k = 0; k < feet.count; ++k) best = std::min(best, s(feet.u[k], feet.v[k]).Distance(x));
  return best;
}

std::vector<gp_Pnt> randomPoints(int n, double half, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> d(-half, half);
  std::vector<gp_Pnt> points;
  for (int i = 0; i < n; ++i) points.emplace_back(d(rng), d(rng), d(rng));
  return points;
}

const gp_Ax3 kFrame(gp_Pnt(1, -2, 0.5), gp_Dir(0.2, 0.3, 1), gp_Dir(1, 0, -0.2));

void expectFeetOf(const Surface& s, const std::function<SurfaceFeet(const gp_Pnt&)>& feet, double u0, double u1,
                  double v0, double v1, double half) {
  for (const gp_Pnt& x : randomPoints(60, half)) {
    const SurfaceFeet f = feet(x);
    ASSERT_GE(f.count, 1);
    EXPECT_NEAR(bestOf(f, s, x), bruteForce(s, x, u0, u1, v0, v1), 1e-7) << x.X() << " " << x.Y() << " " << x.Z();
    for (int k = 0; k < f.count; ++k) EXPECT_TRUE(isLocalMinimum(s, x, f.u[k], f.v[k])) << k;
  }
}

TEST(ClosedFormFoot, CylinderAndSphereAndPlane) {
  const gp_Cylinder cylinder(kFrame, 3);
  expectFeetOf([&](double u, double v) { return ElSLib::Value(u, v, cylinder); },
               [&](const gp_Pnt& x) { return cylinderFeet(cylinder, x); }, 0, 2 * M_PI, -20, 20, 8);
  const gp_Sphere sphere(kFrame, 4);
  expectFeetOf([&](double u, double v) { return ElSLib::Value(u, v, sphere); },
               [&](const gp_Pnt& x) { return sphereFeet(sphere, x); }, 0, 2 * M_PI, -M_PI / 2, M_PI / 2, 8);
  const gp_Pln plane(kFrame);
  expectFeetOf([&](double u, double v) { return ElSLib::Value(u, v, plane); },
               [&](const gp_Pnt& x) { return planeFeet(plane, x); }, -30, 30, -30, 30, 8);
}

// Both nappes of the cone, apex included: the feet on the far nappe are what a face on it
// (a countersink seen from the other side) needs.
TEST(ClosedFormFoot, ConeBothNappes) {
  const gp_Cone cone(kFrame, 0.4, 2);
  const Surface s = [&](double u, double v) { return ElSLib::Value(u, v, cone); };
  expectFeetOf(s, [&](const gp_Pnt& x) { return coneFeet(cone, x); }, 0, 2 * M_PI, -15, 15, 6);
  // A point that has a local minimum on each nappe lists both.
  int both = 0;
  for (const gp_Pnt& x : randomPoints(200, 6)) both += coneFeet(cone, x).count == 2;
  EXPECT_GT(both, 10);
}

TEST(ClosedFormFoot, RingAppleAndLemonTori) {
  for (const auto& [R, r] : {std::pair{5.0, 2.0}, {2.0, 5.0}, {1.0, 6.0}}) {
    const gp_Torus torus(kFrame, R, r);
    const Surface s = [&](double u, double v) { return ElSLib::Value(u, v, torus); };
    expectFeetOf(s, [&](const gp_Pnt& x) { return torusFeet(torus, x); }, 0, 2 * M_PI, 0, 2 * M_PI, R + r + 2);
  }
}

TEST(ClosedFormFoot, AppleTorusListsTheFootAcrossTheAxis) {
  // Minor radius above the major: the meridian circle of the far half reaches across the
  // axis, so a point there has a local minimum on each half.
  const gp_Torus torus(gp_Ax3(), 2, 5);
  const SurfaceFeet f = torusFeet(torus, gp_Pnt(3, 0, 4));
  ASSERT_EQ(f.count, 2);
  EXPECT_NEAR(std::remainder(f.u[1] - f.u[0], 2 * M_PI), M_PI, 1e-12);
}

TEST(ClosedFormFoot, PointsOnTheAxisMayTakeAnyMeridian) {
  const gp_Cylinder cylinder(gp_Ax3(), 3);
  EXPECT_TRUE(cylinderFeet(cylinder, gp_Pnt(0, 0, 4)).anyU);
  EXPECT_FALSE(cylinderFeet(cylinder, gp_Pnt(1e-3, 0, 4)).anyU);
  const gp_Sphere sphere(gp_Ax3(), 2);
  const SurfaceFeet centre = sphereFeet(sphere, gp_Pnt(0, 0, 0));
  EXPECT_TRUE(centre.anyU && centre.anyV);
  const gp_Torus torus(gp_Ax3(), 5, 2);
  const SurfaceFeet onAxis = torusFeet(torus, gp_Pnt(0, 0, 1));
  EXPECT_TRUE(onAxis.anyU);
  EXPECT_NEAR(ElSLib::Value(1.234, onAxis.v[0], torus).Distance(gp_Pnt(0, 0, 1)),
              bruteForce([&](double u, double v) { return ElSLib::Value(u, v, torus); }, gp_Pnt(0, 0, 1), 0, 2 * M_PI,
                         0, 2 * M_PI),
              1e-7);
}

}  // namespace
}  // namespace hg::geometry::exact
