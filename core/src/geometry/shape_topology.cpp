#include "shape_topology.hpp"

#include <BRep_Tool.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>

namespace hg::geometry {

UnsharedEdges edgesNotShared(const TopoDS_Shape& shape) {
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  UnsharedEdges out;
  for (int i = 1; i <= edgeFaces.Extent(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(edgeFaces.FindKey(i));
    const TopTools_ListOfShape& faces = edgeFaces(i);
    if (BRep_Tool::Degenerated(e)) continue;
    if (faces.Extent() > 2) ++out.nonManifold;
    if (faces.Extent() == 1 && !BRep_Tool::IsClosed(e, TopoDS::Face(faces.First()))) ++out.free;
  }
  return out;
}

}  // namespace hg::geometry
