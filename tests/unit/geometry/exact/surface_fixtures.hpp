#pragma once
// Freeform surfaces and curves for the tests of the exact back end's internals, in
// millimetres: a wavy B-spline face and a wavy B-spline curve.
#include <BRepBuilderAPI_MakeFace.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TopoDS_Face.hxx>

#include <cmath>

namespace hg::test {

// Uniform clamped knots for `poles` control points of a cubic.
inline void uniformKnots(int poles, TColStd_Array1OfReal& knots, TColStd_Array1OfInteger& mults) {
  const int n = poles - 2;  // distinct knots of a clamped cubic
  knots.Resize(1, n, false);
  mults.Resize(1, n, false);
  for (int i = 1; i <= n; ++i) {
    knots(i) = double(i - 1) / (n - 1);
    mults(i) = (i == 1 || i == n) ? 4 : 1;
  }
}

// A bicubic B-spline over 60 x 50 mm whose control net follows z = 6 sin(x / 8) cos(y / 10):
// bumps and dips, so that some points have several local minima of their distance to it.
inline Handle(Geom_BSplineSurface) wavySurface() {
  TColgp_Array2OfPnt poles(1, 13, 1, 11);
  for (int i = 1; i <= 13; ++i)
    for (int j = 1; j <= 11; ++j) {
      const double x = 5.0 * (i - 7), y = 5.0 * (j - 6);
      poles(i, j) = gp_Pnt(x, y, 6 * std::sin(x / 8) * std::cos(y / 10));
    }
  TColStd_Array1OfReal uKnots(1, 1), vKnots(1, 1);
  TColStd_Array1OfInteger uMults(1, 1), vMults(1, 1);
  uniformKnots(13, uKnots, uMults);
  uniformKnots(11, vKnots, vMults);
  return new Geom_BSplineSurface(poles, uKnots, vKnots, uMults, vMults, 3, 3);
}

inline TopoDS_Face wavyFace() { return BRepBuilderAPI_MakeFace(wavySurface(), 1e-7).Face(); }

// Two round dips in a flat sheet, 20 mm apart along x, the left one 0.3 mm deeper: from
// below the sheet both are local minima of the distance, the left one the closer.
inline TopoDS_Face twoDipsFace() {
  TColgp_Array2OfPnt poles(1, 17, 1, 9);
  for (int i = 1; i <= 17; ++i)
    for (int j = 1; j <= 9; ++j) {
      const double x = 2.5 * (i - 9), y = 2.5 * (j - 5);
      const double dip = [&](double cx, double depth) { return depth * std::exp(-((x - cx) * (x - cx) + y * y) / 30); }
          (-10, 4.3) + [&](double cx, double depth) { return depth * std::exp(-((x - cx) * (x - cx) + y * y) / 30); }(10, 4.0);
      poles(i, j) = gp_Pnt(x, y, -dip);
    }
  TColStd_Array1OfReal uKnots(1, 1), vKnots(1, 1);
  TColStd_Array1OfInteger uMults(1, 1), vMults(1, 1);
  uniformKnots(17, uKnots, uMults);
  uniformKnots(9, vKnots, vMults);
  return BRepBuilderAPI_MakeFace(new Geom_BSplineSurface(poles, uKnots, vKnots, uMults, vMults, 3, 3), 1e-7).Face();
}

// A cubic B-spline whose control polygon follows y = 8 sin(x / 6), z = 0, x in [-30, 30] mm.
inline Handle(Geom_BSplineCurve) wavyCurve() {
  TColgp_Array1OfPnt poles(1, 13);
  for (int i = 1; i <= 13; ++i) {
    const double x = 5.0 * (i - 7);
    poles(i) = gp_Pnt(x, 8 * std::sin(x / 6), 0);
  }
  TColStd_Array1OfReal knots(1, 1);
  TColStd_Array1OfInteger mults(1, 1);
  uniformKnots(13, knots, mults);
  return new Geom_BSplineCurve(poles, knots, mults, 3);
}

}  // namespace hg::test
