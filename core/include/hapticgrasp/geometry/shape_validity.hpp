#pragma once
// Is a B-rep valid? BRepCheck_Analyzer's checks (what FreeCAD's isValid() runs), with one
// change that keeps them fast: the analyzer classifies every wire of a face against every
// other one, which is quadratic in the wires (1.9 s on the sample plate, whose top and
// bottom faces hold 1025 wires each); here a face with many wires compares a wire only
// with the wires whose 2D boxes can hold it, and reaches the same verdict.
#include <BRepCheck_Status.hxx>
#include <TopoDS_Shape.hxx>

#include <optional>
#include <string>

namespace hg::geometry {

// The first thing the check objects to: a sub-shape, the shape in whose context it is
// wrong (null when it is wrong on its own), and what.
struct ValidityProblem {
  TopoDS_Shape shape;
  TopoDS_Shape context;
  BRepCheck_Status status = BRepCheck_NoError;
};

// Vertices first, then edges, wires, faces, shells, solids (as BRepCheck_Analyzer's
// results are usually read); nothing when the shape is valid. Serial: loading runs beside
// a GUI and a servo thread.
std::optional<ValidityProblem> firstValidityProblem(const TopoDS_Shape& shape);

// In words, sub-shapes numbered as TopExp::MapShapes numbers them in `numbering` (the whole
// part): "self-intersecting wire in face 12", "edge 3 in face 5: BRepCheck_InvalidCurveOnSurface".
std::string describe(const ValidityProblem& problem, const TopoDS_Shape& numbering);

}  // namespace hg::geometry
