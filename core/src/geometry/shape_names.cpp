#include "shape_names.hpp"

#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>

namespace hg::geometry {

const char* shapeTypeName(TopAbs_ShapeEnum type) {
  switch (type) {
    case TopAbs_COMPOUND: return "compound";
    case TopAbs_COMPSOLID: return "compsolid";
    case TopAbs_SOLID: return "solid";
    case TopAbs_SHELL: return "shell";
    case TopAbs_FACE: return "face";
    case TopAbs_WIRE: return "wire";
    case TopAbs_EDGE: return "edge";
    case TopAbs_VERTEX: return "vertex";
    default: return "shape";
  }
}

std::string subShapeName(const TopoDS_Shape& whole, const TopoDS_Shape& sub) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(whole, sub.ShapeType(), map);
  const int index = map.FindIndex(sub);
  return std::string(shapeTypeName(sub.ShapeType())) + " " + (index > 0 ? std::to_string(index) : std::string("?"));
}

}  // namespace hg::geometry
