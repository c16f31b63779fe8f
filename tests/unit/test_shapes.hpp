#pragma once
// Shapes for tests, built with OpenCASCADE in millimetres, and random points around them.
#include <BRepAdaptor_Curve.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepLib.hxx>
#include <BRepOffsetAPI_MakePipeShell.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRep_Builder.hxx>
#include <Geom2d_Line.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Solid.hxx>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Elips.hxx>
#include <gp_Lin2d.hxx>
#include <gp_Pln.hxx>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

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

// ---------------------------------------------------------------------------------------
// Shapes that test loading (mm): compounds of solids as one part, and defects.

inline TopoDS_Compound compoundOf(std::initializer_list<TopoDS_Shape> shapes) {
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  for (const TopoDS_Shape& s : shapes) builder.Add(compound, s);
  return compound;
}

// A sphere poking through the top of a slab: the faces meet in a circle inside both, and
// no edge of either crosses the other (the sphere's seam and poles stay below the slab's
// top face).
inline TopoDS_Shape sphereThroughSlab() {
  const TopoDS_Shape sphere = BRepPrimAPI_MakeSphere(gp_Ax2(gp::Origin(), gp::DX(), -gp::DY()), 5).Shape();
  const TopoDS_Shape slab = BRepPrimAPI_MakeBox(gp_Pnt(-20, -20, -20), 40, 40, 23).Shape();
  return compoundOf({sphere, slab});
}

// A bolt through a hexagonal nut whose hole has the bolt's radius: coincident cylinders.
inline TopoDS_Shape boltInNut(double boltRadius) {
  BRepBuilderAPI_MakePolygon hexagon;
  for (int k = 0; k < 6; ++k) hexagon.Add(gp_Pnt(8 * std::cos(k * std::numbers::pi / 3), 8 * std::sin(k * std::numbers::pi / 3), 0));
  hexagon.Close();
  const TopoDS_Shape prism =
      BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeFace(hexagon.Wire()).Face(), gp_Vec(0, 0, 6)).Shape();
  const TopoDS_Shape hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -1), gp::DZ()), 4, 8).Shape();
  const TopoDS_Shape nut = BRepAlgoAPI_Cut(prism, hole).Shape();
  const TopoDS_Shape bolt = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -10), gp::DZ()), boltRadius, 30).Shape();
  return compoundOf({bolt, nut});
}

// A square prism whose top is turned by `twist` against its bottom, the sides split into
// planar triangles and sewn into one solid. Turned far enough, the sides cross each other.
inline TopoDS_Shape twistedPrism(double twist) {
  const int n = 4;
  const double radius = 10, height = 3;
  std::vector<gp_Pnt> bottom, top;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    bottom.emplace_back(radius * std::cos(a), radius * std::sin(a), 0);
    top.emplace_back(radius * std::cos(a + twist), radius * std::sin(a + twist), height);
  }
  BRepBuilderAPI_Sewing sewing;
  auto face = [&](BRepBuilderAPI_MakePolygon polygon) { sewing.Add(BRepBuilderAPI_MakeFace(polygon.Wire()).Face()); };
  BRepBuilderAPI_MakePolygon bottomCap, topCap;
  for (int i = n - 1; i >= 0; --i) bottomCap.Add(bottom[i]);
  for (int i = 0; i < n; ++i) topCap.Add(top[i]);
  bottomCap.Close();
  topCap.Close();
  face(bottomCap);
  face(topCap);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    face(BRepBuilderAPI_MakePolygon(bottom[i], bottom[j], top[j], true));
    face(BRepBuilderAPI_MakePolygon(bottom[i], top[j], top[i], true));
  }
  sewing.Perform();
  TopoDS_Solid solid;
  BRep_Builder builder;
  builder.MakeSolid(solid);
  for (TopExp_Explorer ex(sewing.SewedShape(), TopAbs_SHELL); ex.More(); ex.Next()) builder.Add(solid, ex.Current());
  return solid;
}

// A prism whose outline loops over itself at one corner: its top and bottom wires cross
// themselves (FreeCAD displays it; isValid() is false), two of its sides cross.
inline TopoDS_Shape loopPrism() {
  BRepBuilderAPI_MakePolygon outline;
  for (const auto& [x, y] : {std::pair{10., 10.}, {0., 10.}, {0., 0.}, {-1., -1.}, {-1., 0.}, {0., -1.}, {10., -1.}})
    outline.Add(gp_Pnt(x, y, 0));
  outline.Close();
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(gp_Pln(gp::XOY()), outline.Wire(), true).Face();
  return BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 5)).Shape();
}

// The thread of a screw: a triangular profile swept along a helix (pitch 1.5 mm, 20 mm
// high, radius 4 mm) into one solid of five faces, three of them B-spline surfaces, as
// FreeCAD's Part.Wire(makeHelix(...)).makePipeShell([profile], True, True) makes it.
inline TopoDS_Shape helicalThread() {
  const double pitch = 1.5, height = 20, radius = 4;
  const Handle(Geom_CylindricalSurface) cylinder = new Geom_CylindricalSurface(gp_Ax3(gp::XOY()), radius);
  const gp_Lin2d line(gp_Pnt2d(0, 0), gp_Dir2d(2 * std::numbers::pi, pitch));
  const double length = std::hypot(2 * std::numbers::pi, pitch) * height / pitch;
  const TopoDS_Edge helix = BRepBuilderAPI_MakeEdge(new Geom2d_Line(line), cylinder, 0, length).Edge();
  BRepLib::BuildCurves3d(helix);
  const TopoDS_Wire profile =
      BRepBuilderAPI_MakePolygon(gp_Pnt(radius, 0, 0), gp_Pnt(radius + 1, 0, 0.6), gp_Pnt(radius, 0, 1.2), true).Wire();
  BRepOffsetAPI_MakePipeShell pipe(BRepBuilderAPI_MakeWire(helix).Wire());
  pipe.SetMode(true);  // Frenet, as FreeCAD's makePipeShell(..., True, True)
  pipe.Add(profile);
  pipe.Build();
  pipe.MakeSolid();
  return pipe.Shape();
}

// Points in a shell of +/- `shell_m` around the surface (area-weighted surface points
// moved along the normal).
inline std::vector<Vec3> shellPoints(const PartModel& part, int count, double shell_m, unsigned seed = 1) {
  std::mt19937 rng(seed);
  return geometry::SurfaceSampler(part, 1e-3).shell(count, shell_m, rng);
}

}  // namespace hg::test
