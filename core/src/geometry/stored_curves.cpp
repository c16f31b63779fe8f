#include "stored_curves.hpp"

#include <BRep_GCurve.hxx>
#include <BRep_TEdge.hxx>
#include <BRep_Tool.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>

#include "shape_names.hpp"

namespace hg::geometry {

std::vector<StoredCurveOnFace> storedCurvesOnFaces(const TopoDS_Edge& edge) {
  std::vector<StoredCurveOnFace> stored;
  const auto& tedge = static_cast<const BRep_TEdge&>(*edge.TShape());
  for (BRep_ListIteratorOfListOfCurveRepresentation r(tedge.Curves()); r.More(); r.Next()) {
    if (!r.Value()->IsCurveOnSurface()) continue;
    const auto& on = static_cast<const BRep_GCurve&>(*r.Value());
    double first = 0, last = 0;
    on.Range(first, last);
    const Handle(Geom2d_Curve) second = on.IsCurveOnClosedSurface() ? on.PCurve2() : Handle(Geom2d_Curve)();
    for (const Handle(Geom2d_Curve)& curve : {on.PCurve(), second})
      if (!curve.IsNull()) stored.push_back({curve, first, last, r.Value()});
  }
  return stored;
}

std::string faceOf(const TopoDS_Shape& shape, const TopoDS_Edge& edge, const StoredCurveOnFace& stored) {
  for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next()) {
    TopLoc_Location location;
    const Handle(Geom_Surface) surface = BRep_Tool::Surface(TopoDS::Face(f.Current()), location);
    if (stored.on->IsCurveOnSurface(surface, location.Predivided(edge.Location())))
      return subShapeName(shape, f.Current());
  }
  return "a face";
}

}  // namespace hg::geometry
