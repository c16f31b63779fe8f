#include "rational_weights.hpp"

#include <BRep_Tool.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_BezierCurve.hxx>
#include <Geom2d_OffsetCurve.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_BezierCurve.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_OffsetCurve.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SweptSurface.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>

#include <algorithm>
#include <cstdio>
#include <functional>

#include "shape_names.hpp"
#include "stored_curves.hpp"

namespace hg::geometry {
namespace {

// Largest over smallest weight; 1 for a curve or surface without weights. OCCT refuses a
// weight at or below gp::Resolution() when it builds one, so the smallest is positive.
double spread(const TColStd_Array1OfReal& weights) {
  const auto [lo, hi] = std::minmax_element(weights.begin(), weights.end());
  return *hi / *lo;
}

double spread(const TColStd_Array2OfReal& weights) {
  double lo = weights(weights.LowerRow(), weights.LowerCol()), hi = lo;
  for (int i = weights.LowerRow(); i <= weights.UpperRow(); ++i)
    for (int j = weights.LowerCol(); j <= weights.UpperCol(); ++j)
      lo = std::min(lo, weights(i, j)), hi = std::max(hi, weights(i, j));
  return hi / lo;
}

template <class Curve>
double curveSpread(const Curve& curve) {
  if (!curve->IsRational()) return 1;
  TColStd_Array1OfReal weights(1, curve->NbPoles());
  curve->Weights(weights);
  return spread(weights);
}

template <class Surface>
double surfaceSpread(const Surface& surface) {
  if (!surface->IsURational() && !surface->IsVRational()) return 1;
  TColStd_Array2OfReal weights(1, surface->NbUPoles(), 1, surface->NbVPoles());
  surface->Weights(weights);
  return spread(weights);
}

// A 3D curve or a curve on a face, down through trims and offsets to what it is made from.
template <class Trimmed, class Offset, class BSpline, class Bezier, class Curve>
double madeFromSpread(opencascade::handle<Curve> curve) {
  while (true) {
    if (const auto t = opencascade::handle<Trimmed>::DownCast(curve)) curve = t->BasisCurve();
    else if (const auto o = opencascade::handle<Offset>::DownCast(curve)) curve = o->BasisCurve();
    else break;
  }
  if (const auto b = opencascade::handle<BSpline>::DownCast(curve)) return curveSpread(b);
  if (const auto b = opencascade::handle<Bezier>::DownCast(curve)) return curveSpread(b);
  return 1;
}

double weightSpread(const Handle(Geom_Curve)& curve) {
  return madeFromSpread<Geom_TrimmedCurve, Geom_OffsetCurve, Geom_BSplineCurve, Geom_BezierCurve>(curve);
}

double weightSpread(const Handle(Geom2d_Curve)& curve) {
  return madeFromSpread<Geom2d_TrimmedCurve, Geom2d_OffsetCurve, Geom2d_BSplineCurve, Geom2d_BezierCurve>(curve);
}

double weightSpread(Handle(Geom_Surface) surface) {
  while (true) {
    if (const auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(surface)) surface = t->BasisSurface();
    else if (const auto o = Handle(Geom_OffsetSurface)::DownCast(surface)) surface = o->BasisSurface();
    else break;
  }
  if (const auto b = Handle(Geom_BSplineSurface)::DownCast(surface)) return surfaceSpread(b);
  if (const auto b = Handle(Geom_BezierSurface)::DownCast(surface)) return surfaceSpread(b);
  if (const auto s = Handle(Geom_SweptSurface)::DownCast(surface)) return weightSpread(s->BasisCurve());
  return 1;
}

void widen(WeightSpread& widest, double spread, const std::function<std::string()>& where) {
  if (spread > widest.spread) widest = {spread, where()};  // OCCT refuses weights that would give NaN
}

}  // namespace

WeightSpread widestWeights(const TopoDS_Shape& shape) {
  WeightSpread widest;
  for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next()) {
    TopLoc_Location location;
    if (const Handle(Geom_Surface) surface = BRep_Tool::Surface(TopoDS::Face(f.Current()), location); !surface.IsNull())
      widen(widest, weightSpread(surface), [&] { return subShapeName(shape, f.Current()) + "'s surface"; });
  }
  for (TopExp_Explorer e(shape, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    double first = 0, last = 0;
    if (const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, first, last); !curve.IsNull())
      widen(widest, weightSpread(curve), [&] { return subShapeName(shape, edge) + "'s curve"; });
    for (const StoredCurveOnFace& stored : storedCurvesOnFaces(edge))  // never a made-up one
      widen(widest, weightSpread(stored.curve),
            [&] { return subShapeName(shape, edge) + "'s curve on " + faceOf(shape, edge, stored); });
  }
  return widest;
}

std::string weightsTooFarApart(const TopoDS_Shape& shape) {
  const WeightSpread widest = widestWeights(shape);
  if (widest.spread <= kMaxWeightRatio) return "";
  char text[64];
  std::snprintf(text, sizeof text, " has weights %.3g times apart", widest.spread);
  return widest.where + text;
}

}  // namespace hg::geometry
