#include "shape_healing.hpp"

#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <Precision.hxx>
#include <ShapeExtend_Status.hxx>
#include <ShapeFix_Shape.hxx>
#include <ShapeFix_Wire.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shell.hxx>

#include <cmath>

#include "shape_names.hpp"
#include "shape_topology.hpp"

namespace hg::geometry {

TopoDS_Shape healWithShapeFix(const TopoDS_Shape& shape, double precision, double maxTolerance) {
  try {
    ShapeFix_Shape fix(shape);
    fix.SetPrecision(precision);
    fix.SetMinTolerance(precision);
    fix.SetMaxTolerance(maxTolerance);
    const Handle(ShapeFix_Wire)& wires = fix.FixWireTool();
    wires->FixSelfIntersectionMode() = 1;
    wires->FixSelfIntersectingEdgeMode() = 1;
    wires->FixIntersectingEdgesMode() = 1;
    wires->FixNonAdjacentIntersectingEdgesMode() = 1;
    fix.Perform();
    const TopoDS_Shape healed = fix.Shape();
    return healed.IsNull() || !fix.Status(ShapeExtend_DONE) ? shape : healed;
  } catch (const Standard_Failure&) {
    return shape;
  }
}

std::string unhealable(const TopoDS_Shape& shape) {
  for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next()) {
    const TopoDS_Face& face = TopoDS::Face(f.Current());
    for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) {
      const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
      double first = 0, last = 0;
      if (BRep_Tool::CurveOnSurface(edge, face, first, last).IsNull()) continue;  // ShapeFix makes one
      if (std::isfinite(first) && std::isfinite(last) && last - first > Precision::PConfusion()) continue;
      return subShapeName(shape, edge) + " has an empty parameter range on " + subShapeName(shape, face);
    }
  }
  return "";
}

TopoDS_Shape sewIntoSolids(const TopoDS_Shape& shape, double tolerance, int& freeEdges) {
  TopoDS_Compound solids;
  BRep_Builder builder;
  builder.MakeCompound(solids);
  freeEdges = -1;
  try {
    BRepBuilderAPI_Sewing sewing(tolerance);
    for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) sewing.Add(ex.Current());
    sewing.Perform();
    freeEdges = sewing.NbFreeEdges();
    for (TopExp_Explorer ex(sewing.SewedShape(), TopAbs_SHELL); ex.More(); ex.Next()) {
      const TopoDS_Shell& shell = TopoDS::Shell(ex.Current());
      if (edgesNotShared(shell).free == 0) builder.Add(solids, BRepBuilderAPI_MakeSolid(shell).Solid());
    }
  } catch (const Standard_Failure&) {
    freeEdges = -1;
  }
  return solids;
}

}  // namespace hg::geometry
