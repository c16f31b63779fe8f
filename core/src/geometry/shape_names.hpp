#pragma once
// Sub-shapes in words, numbered 1..N in TopExp::MapShapes order as PartModel numbers them.
#include <TopoDS_Shape.hxx>

#include <string>

namespace hg::geometry {

const char* shapeTypeName(TopAbs_ShapeEnum type);
// "face 12"; "face ?" when `sub` is not a sub-shape of `whole`.
std::string subShapeName(const TopoDS_Shape& whole, const TopoDS_Shape& sub);

}  // namespace hg::geometry
