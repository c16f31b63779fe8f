#pragma once
// Repairs tried on a part before it is given up: ShapeFix for an invalid or self-crossing
// B-rep, sewing for faces that leave gaps. Each returns a new shape; the input is never
// modified.
#include <TopoDS_Shape.hxx>

#include <string>

namespace hg::geometry {

// ShapeFix_Shape as FreeCAD's Part fix() runs it, with every wire fix on (self-intersecting
// and intersecting edges, adjacent or not) but not the fix of a face's wires crossing one
// another (it looped on a damaged part): tolerances may grow up to maxTolerance (shape
// units). Returns the input itself when ShapeFix fails or finds nothing to do.
TopoDS_Shape healWithShapeFix(const TopoDS_Shape& shape, double precision, double maxTolerance);

// Why ShapeFix must not be run on `shape`, or "" if it may: an edge whose curve on a face
// has an empty or non-finite parameter range. ShapeFix's classifier then looks for a point
// of the face 1e100 away and brings it into the surface's period one period at a time
// (BRepTopAdaptor_FClass2d), forever (found by fuzz_brep). No file a CAD system writes has
// one; such a part goes to a robust back end unhealed.
std::string unhealable(const TopoDS_Shape& shape);

// BRepBuilderAPI_Sewing of all the faces of `shape` within `tolerance` (shape units): the
// closed shells it makes, each made a solid, in a compound (empty when it closes none);
// `freeEdges` is what is still open.
TopoDS_Shape sewIntoSolids(const TopoDS_Shape& shape, double tolerance, int& freeEdges);

}  // namespace hg::geometry
