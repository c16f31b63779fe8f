#include "shape_healing.hpp"

#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRep_Builder.hxx>
#include <ShapeExtend_Status.hxx>
#include <ShapeFix_Face.hxx>
#include <ShapeFix_Shape.hxx>
#include <ShapeFix_Shell.hxx>
#include <ShapeFix_Solid.hxx>
#include <ShapeFix_Wire.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>

#include "curve_on_face.hpp"
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
    // Not between the wires of a face: its intersection of their curves on the face (made
    // up by projection where an edge has none) ran 88 s in Release on a damaged extrusion
    // (fuzz_brep), where no progress indicator is asked. Such a face stays unhealed and its
    // part loads on a robust back end, the defect named.
    fix.FixSolidTool()->FixShellTool()->FixFaceTool()->FixIntersectingWiresMode() = 0;
    fix.Perform();
    const TopoDS_Shape healed = fix.Shape();
    return healed.IsNull() || !fix.Status(ShapeExtend_DONE) ? shape : healed;
  } catch (const Standard_Failure&) {
    return shape;
  }
}

std::string unhealable(const TopoDS_Shape& shape) {
  return firstCurveOnFace(shape, [](const CurveOnFace& c) -> std::string {
    return c.emptyRange() ? "has an empty parameter range" : "";
  });
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
