#pragma once
// The curves an edge stores on its faces, read from the edge itself. BRep_Tool::CurveOnSurface
// makes one up for a plane that has none stored, by a projection that can itself loop on a
// damaged part: the checks that run before any OCCT algorithm read only what is stored.
#include <BRep_CurveRepresentation.hxx>
#include <Geom2d_Curve.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Shape.hxx>

#include <string>
#include <vector>

namespace hg::geometry {

struct StoredCurveOnFace {
  Handle(Geom2d_Curve) curve;  // one of a seam's two, or the only one
  double first = 0, last = 0;
  Handle(BRep_CurveRepresentation) on;  // which face's surface it lies on
};
std::vector<StoredCurveOnFace> storedCurvesOnFaces(const TopoDS_Edge& edge);

// The face of `shape` that `stored` lies on, in words ("face 4"), or "a face".
std::string faceOf(const TopoDS_Shape& shape, const TopoDS_Edge& edge, const StoredCurveOnFace& stored);

}  // namespace hg::geometry
