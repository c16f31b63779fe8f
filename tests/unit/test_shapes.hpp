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
#include <BRepTools.hxx>
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

#include <BRepAlgoAPI_Common.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepOffsetAPI_MakeThickSolid.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRep_Builder.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <GeomAPI_PointsToBSplineSurface.hxx>
#include <Geom_BezierCurve.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_OffsetCurve.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopoDS_Compound.hxx>

#include <map>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/geometry/surface_sampler.hpp"

namespace hg::test {

using geometry::LengthUnit;
using geometry::PartModel;
using geometry::PartModelPtr;

// A BREP file as OCCT reads it, in its own units; a file that does not read fails the test
// that asked for it, naming the file.
inline TopoDS_Shape readShape(const std::filesystem::path& path) {
  TopoDS_Shape shape;
  BRep_Builder builder;
  if (!BRepTools::Read(shape, path.c_str(), builder)) throw std::runtime_error("cannot read " + path.string());
  return shape;
}

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

// --- Parts with faces on every kind of surface and edges on every kind of curve ---------

inline PartModelPtr part(const TopoDS_Shape& shape, const std::string& name) {
  return PartModel::fromShape(shape, LengthUnit::Millimetre, name);
}

// How many faces of each surface type, and edges of each curve type, a part has.
inline std::map<GeomAbs_SurfaceType, int> surfaceTypes(const PartModel& p) {
  std::map<GeomAbs_SurfaceType, int> types;
  for (int i = 1; i <= p.faces().Extent(); ++i) ++types[BRepAdaptor_Surface(TopoDS::Face(p.faces()(i))).GetType()];
  return types;
}
inline std::map<GeomAbs_CurveType, int> curveTypes(const PartModel& p) {
  std::map<GeomAbs_CurveType, int> types;
  for (int i = 1; i <= p.edges().Extent(); ++i)
    if (!BRep_Tool::Degenerated(TopoDS::Edge(p.edges()(i)))) ++types[BRepAdaptor_Curve(TopoDS::Edge(p.edges()(i))).GetType()];
  return types;
}

inline Handle(Geom_BSplineCurve) interpolate(const std::vector<gp_Pnt>& points, bool periodic = false) {
  Handle(TColgp_HArray1OfPnt) array = new TColgp_HArray1OfPnt(1, static_cast<int>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) array->SetValue(static_cast<int>(i) + 1, points[i]);
  GeomAPI_Interpolate interpolation(array, periodic, 1e-9);
  interpolation.Perform();
  return interpolation.Curve();
}

inline TopoDS_Wire wireOf(std::initializer_list<TopoDS_Edge> edges) {
  BRepBuilderAPI_MakeWire wire;
  for (const TopoDS_Edge& e : edges) wire.Add(e);
  return wire.Wire();
}

// A vase: a B-spline profile revolved about z (a face on a surface of revolution) between
// two planar discs.
inline PartModelPtr revolvedSplinePart() {
  const Handle(Geom_BSplineCurve) profile =
      interpolate({gp_Pnt(20, 0, 0), gp_Pnt(27, 0, 12), gp_Pnt(16, 0, 26), gp_Pnt(22, 0, 40)});
  const TopoDS_Wire wire = wireOf({BRepBuilderAPI_MakeEdge(profile).Edge(),
                                   BRepBuilderAPI_MakeEdge(gp_Pnt(22, 0, 40), gp_Pnt(0, 0, 40)).Edge(),
                                   BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 40), gp_Pnt(0, 0, 0)).Edge(),
                                   BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(20, 0, 0)).Edge()});
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(wire, true).Face();
  return part(BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1))).Shape(), "vase");
}

// A cam: a closed B-spline extruded along z (a face on a surface of linear extrusion).
inline PartModelPtr extrudedSplinePart() {
  std::vector<gp_Pnt> points;
  for (int k = 0; k < 8; ++k) {
    const double a = 2 * M_PI * k / 8, r = 20 + 6 * std::cos(2 * a) + 3 * std::sin(3 * a);
    points.emplace_back(r * std::cos(a), r * std::sin(a), 0);
  }
  const TopoDS_Edge edge = BRepBuilderAPI_MakeEdge(interpolate(points, true)).Edge();
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakeWire(edge).Wire(), true).Face();
  return part(BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 25)).Shape(), "cam");
}

// A cone with its apex (and a degenerated edge there).
inline PartModelPtr conePart() {
  return part(BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(0, 0, -20), gp_Dir(0, 0, 1)), 25, 0, 40).Shape(), "cone");
}

inline PartModelPtr torusPart(double major, double minor) {
  return part(BRepPrimAPI_MakeTorus(gp_Ax2(), major, minor).Shape(), "torus");
}

// A slab whose bottom and top are a Bézier patch, its sides extrusions of Bézier curves.
inline PartModelPtr bezierPart() {
  TColgp_Array2OfPnt poles(1, 3, 1, 3);
  for (int i = 1; i <= 3; ++i)
    for (int j = 1; j <= 3; ++j) poles(i, j) = gp_Pnt(20.0 * (i - 2), 20.0 * (j - 2), (i == 2 && j == 2) ? 12 : 3.0 * (i - j));
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(new Geom_BezierSurface(poles), 1e-7).Face();
  return part(BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 8)).Shape(), "bezier slab");
}

// A block of a rectangular trim of a wavy B-spline surface, extruded down.
inline PartModelPtr trimmedSurfacePart() {
  TColgp_Array2OfPnt points(1, 7, 1, 7);
  for (int i = 1; i <= 7; ++i)
    for (int j = 1; j <= 7; ++j) {
      const double x = 8.0 * (i - 4), y = 8.0 * (j - 4);
      points(i, j) = gp_Pnt(x, y, 4 * std::sin(x / 9) * std::cos(y / 11));
    }
  const Handle(Geom_BSplineSurface) s = GeomAPI_PointsToBSplineSurface(points).Surface();
  double u0, u1, v0, v1;
  s->Bounds(u0, u1, v0, v1);
  const Handle(Geom_Surface) trimmed =
      new Geom_RectangularTrimmedSurface(s, u0 + 0.1 * (u1 - u0), u1 - 0.2 * (u1 - u0), v0 + 0.15 * (v1 - v0), v1);
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(trimmed, 1e-7).Face();
  return part(BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, -15)).Shape(), "trimmed wave");
}

// The loft hollowed to a 2 mm wall, open at the top, as FreeCAD's Thickness makes a shell:
// the inner face lies on an offset surface of the B-spline side.
inline PartModelPtr thickLoftPart() {
  const TopoDS_Shape loft = loftPart()->shape();
  TopTools_ListOfShape open;
  double top = -INFINITY;
  for (TopExp_Explorer ex(loft, TopAbs_FACE); ex.More(); ex.Next()) {
    const BRepAdaptor_Surface s(TopoDS::Face(ex.Current()));
    if (s.GetType() == GeomAbs_Plane && s.Plane().Location().Z() > top) {
      top = s.Plane().Location().Z();
      open.Clear();
      open.Append(ex.Current());
    }
  }
  BRepOffsetAPI_MakeThickSolid shell;
  shell.MakeThickSolidByJoin(loft, open, -2.0, 1e-4);
  return part(shell.Shape(), "hollow loft");
}

// A plate whose one side is the offset of a B-spline (an edge on an offset curve, and a
// face on its extrusion), and whose top is cut by a Bézier curve.
inline PartModelPtr offsetCurvePart() {
  const Handle(Geom_BSplineCurve) wave = interpolate({gp_Pnt(0, 0, 0), gp_Pnt(10, 4, 0), gp_Pnt(20, -3, 0), gp_Pnt(30, 2, 0)});
  const Handle(Geom_Curve) side = new Geom_OffsetCurve(wave, -5, gp_Dir(0, 0, 1));
  const gp_Pnt a = side->Value(side->FirstParameter()), b = side->Value(side->LastParameter());
  TColgp_Array1OfPnt bezierPoles(1, 4);
  bezierPoles(1) = b;
  bezierPoles(2) = gp_Pnt(b.X() + 2, b.Y() + 12, 0);
  bezierPoles(3) = gp_Pnt(a.X() - 2, a.Y() + 16, 0);
  bezierPoles(4) = a;
  const TopoDS_Wire wire = wireOf({BRepBuilderAPI_MakeEdge(side).Edge(),
                                   BRepBuilderAPI_MakeEdge(new Geom_BezierCurve(bezierPoles)).Edge()});
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(wire, true).Face();
  return part(BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 6)).Shape(), "offset curve plate");
}

// Conic sections as edges: a cylinder cut by a tilted plane (an ellipse), a cone cut by a
// plane parallel to its axis (a hyperbola) and by one parallel to a generatrix (a parabola).
inline PartModelPtr conicSectionsPart() {
  const TopoDS_Shape cylinder = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 10, 40).Shape();
  gp_Trsf tilt;
  tilt.SetRotation(gp_Ax1(gp_Pnt(0, 0, 30), gp_Dir(1, 0, 0)), 0.5);
  const TopoDS_Shape below = BRepBuilderAPI_Transform(BRepPrimAPI_MakeBox(gp_Pnt(-50, -50, -20), 100, 100, 50).Shape(), tilt).Shape();
  const TopoDS_Shape ellipse = BRepAlgoAPI_Common(cylinder, below).Shape();
  // A cone (apex up at z = 60, half angle atan(15/20)), its side cut by the plane x = 5
  // (a hyperbola) and, on the other side, by a plane parallel to a generatrix (a parabola).
  const TopoDS_Shape cone = BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(0, 0, 40), gp_Dir(0, 0, 1)), 15, 0, 20).Shape();
  const TopoDS_Shape halfX = BRepPrimAPI_MakeBox(gp_Pnt(-50, -50, 35), 55, 100, 30).Shape();
  gp_Trsf lean;
  lean.SetRotation(gp_Ax1(gp_Pnt(-6, 0, 52), gp_Dir(0, 1, 0)), -std::atan2(15.0, 20.0));
  const TopoDS_Shape parabolic =
      BRepBuilderAPI_Transform(BRepPrimAPI_MakeBox(gp_Pnt(-6, -50, 20), 100, 100, 100).Shape(), lean).Shape();
  const TopoDS_Shape cut = BRepAlgoAPI_Common(BRepAlgoAPI_Common(cone, halfX).Shape(), parabolic).Shape();
  return part(BRepAlgoAPI_Fuse(ellipse, cut).Shape(), "conic sections");
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

// A tube of radius 2 mm swept along a bent B-spline path, capped: inside it, points near
// its centre line are near the focal points of its wall.
inline PartModelPtr sweptTubePart() {
  const Handle(Geom_BSplineCurve) path =
      interpolate({gp_Pnt(0, 0, 0), gp_Pnt(20, 5, 5), gp_Pnt(35, 25, 0), gp_Pnt(30, 45, 15)});
  gp_Pnt start;
  gp_Vec tangent;
  path->D1(path->FirstParameter(), start, tangent);
  const TopoDS_Wire circle =
      BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(start, gp_Dir(tangent)), 2.0)).Edge()).Wire();
  BRepOffsetAPI_MakePipeShell pipe(BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(path).Edge()).Wire());
  pipe.SetMode(true);
  pipe.Add(circle);
  pipe.Build();
  pipe.MakeSolid();
  return part(pipe.Shape(), "swept tube");
}

// Two boxes touching face to face, as one part (a weldment).
inline PartModelPtr touchingBoxesPart() {
  return PartModel::fromShape(compoundOf({BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 40, 30, 20).Shape(),
                                          BRepPrimAPI_MakeBox(gp_Pnt(40, 5, 0), 20, 20, 20).Shape()}),
                              LengthUnit::Millimetre, "weldment");
}

// Points in a shell of +/- `shell_m` around the surface (area-weighted surface points
// moved along the normal).
inline std::vector<Vec3> shellPoints(const PartModel& part, int count, double shell_m, unsigned seed = 1) {
  std::mt19937 rng(seed);
  return geometry::SurfaceSampler(part, 1e-3).shell(count, shell_m, rng);
}

}  // namespace hg::test
