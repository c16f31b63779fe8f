#pragma once
// Repairs tried on a part before it is given up: ShapeFix for an invalid or self-crossing
// B-rep, sewing for faces that leave gaps. Each returns a new shape; the input is never
// modified.
#include <TopoDS_Shape.hxx>

namespace hg::geometry {

// ShapeFix_Shape as FreeCAD's Part fix() runs it, with every wire fix on (self-intersecting
// and intersecting edges, adjacent or not): tolerances may grow up to maxTolerance (shape
// units). Returns the input itself when ShapeFix fails or finds nothing to do.
TopoDS_Shape healWithShapeFix(const TopoDS_Shape& shape, double precision, double maxTolerance);

// BRepBuilderAPI_Sewing of all the faces of `shape` within `tolerance` (shape units): the
// closed shells it makes, each made a solid, in a compound (empty when it closes none);
// `freeEdges` is what is still open.
TopoDS_Shape sewIntoSolids(const TopoDS_Shape& shape, double tolerance, int& freeEdges);

}  // namespace hg::geometry
