#pragma once
// Shapes for tests, built with OpenCASCADE in millimetres, and random points around them.
#include <BRepAdaptor_Curve.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Elips.hxx>

#include <random>
#include <string>

#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/geometry/surface_sampler.hpp"

namespace hg::test {

using geometry::LengthUnit;
using geometry::PartModel;
using geometry::PartModelPtr;

inline PartModelPtr boxPart(double x = 100, double y = 60, double z = 30) {
  return PartModel::fromShape(BRepPrimAPI_MakeBox(gp_Pnt(-x / 2, -y / 2, -z / 2), x, y, z).Shape(),
                              LengthUnit::Millimetre, "box");
}

// The first paper's cylinder: diameter 100 mm, length 400 mm, axis z, centred.
inline PartModelPtr cylinderPart(double diameter = 100, double length = 400, LengthUnit unit = LengthUnit::Millimetre) {
  const gp_Ax2 axis(gp_Pnt(0, 0, -length / 2), gp_Dir(0, 0, 1));
  return PartModel::fromShape(BRepPrimAPI_MakeCylinder(axis, diameter / 2, length).Shape(), unit, "cylinder");
}

inline PartModelPtr spherePart(double radius = 40) {
  return PartModel::fromShape(BRepPrimAPI_MakeSphere(radius).Shape(), LengthUnit::Millimetre, "sphere");
}

// A box with filleted vertical edges and a through hole: planes, cylinders, fillets,
// concave and convex edges.
inline PartModelPtr drilledBlockPart() {
  TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-50, -30, -15), 100, 60, 30).Shape();
  BRepFilletAPI_MakeFillet fillet(box);
  for (TopExp_Explorer ex(box, TopAbs_EDGE); ex.More(); ex.Next()) {
    BRepAdaptor_Curve c(TopoDS::Edge(ex.Current()));
    if (c.GetType() == GeomAbs_Line && std::abs(c.Line().Direction().Z()) > 0.99) fillet.Add(8, TopoDS::Edge(ex.Current()));
  }
  const TopoDS_Shape rounded = fillet.Shape();
  const TopoDS_Shape hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(20, 0, -20), gp_Dir(0, 0, 1)), 8, 40).Shape();
  return PartModel::fromShape(BRepAlgoAPI_Cut(rounded, hole).Shape(), LengthUnit::Millimetre, "drilled block");
}

// A loft through closed sections: one B-spline face, u-closed, plus two planar caps.
inline PartModelPtr loftPart() {
  BRepOffsetAPI_ThruSections loft(true, false);
  const double radii[] = {30, 42, 25, 35};
  for (int i = 0; i < 4; ++i) {
    const gp_Ax2 axis(gp_Pnt(5.0 * (i % 2), 0, 40.0 * i), gp_Dir(0, 0, 1));
    const gp_Elips ellipse(axis, radii[i], radii[i] * 0.7);
    loft.AddWire(BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(ellipse).Edge()).Wire());
  }
  loft.Build();
  return PartModel::fromShape(loft.Shape(), LengthUnit::Millimetre, "loft");
}

// Points in a shell of +/- `shell_m` around the surface (area-weighted surface points
// moved along the normal).
inline std::vector<Vec3> shellPoints(const PartModel& part, int count, double shell_m, unsigned seed = 1) {
  std::mt19937 rng(seed);
  return geometry::SurfaceSampler(part, 1e-3).shell(count, shell_m, rng);
}

}  // namespace hg::test
