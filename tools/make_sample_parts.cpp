// Writes the sample parts of resources/parts, in millimetres, and their parts.json:
//   make_sample_parts <directory>
// The parts are built with OpenCASCADE from scratch, so the files are reproducible: the
// same OCCT gives the same bytes. Each part is read back with PartModel::fromFile (which
// runs BRepCheck and a self-intersection check) before parts.json is written.
#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepFilletAPI_MakeChamfer.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepGProp.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Circ.hxx>
#include <gp_Elips.hxx>
#include <gp_Pln.hxx>

#include <chrono>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "hapticgrasp/geometry/part_model.hpp"

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& what) { throw std::runtime_error(what); }

// Geometric tolerance for selecting edges and faces by position, mm.
constexpr double kTol = 1e-6;

bool near(double a, double b) { return std::abs(a - b) <= kTol; }

// Points along an edge: both ends and three inside.
std::vector<gp_Pnt> samples(const TopoDS_Edge& edge) {
  BRepAdaptor_Curve c(edge);
  std::vector<gp_Pnt> points;
  for (int i = 0; i <= 4; ++i) points.push_back(c.Value(c.FirstParameter() + (c.LastParameter() - c.FirstParameter()) * i / 4));
  return points;
}

// The edges of `shape` (each once, in TopExp's deterministic order) that `keep` accepts.
std::vector<TopoDS_Edge> edgesWhere(const TopoDS_Shape& shape, const std::function<bool(const TopoDS_Edge&)>& keep) {
  TopTools_IndexedMapOfShape edges;
  TopExp::MapShapes(shape, TopAbs_EDGE, edges);
  std::vector<TopoDS_Edge> out;
  for (int i = 1; i <= edges.Extent(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(edges(i));
    if (!BRep_Tool::Degenerated(e) && keep(e)) out.push_back(e);
  }
  return out;
}

bool allAt(const TopoDS_Edge& e, const std::function<bool(const gp_Pnt&)>& test) {
  for (const gp_Pnt& p : samples(e))
    if (!test(p)) return false;
  return true;
}

bool isCircle(const TopoDS_Edge& e, double radius) {
  BRepAdaptor_Curve c(e);
  return c.GetType() == GeomAbs_Circle && near(c.Circle().Radius(), radius);
}

// The planar face at height z facing +z or -z with the largest area.
TopoDS_Face planarFaceAt(const TopoDS_Shape& shape, double z) {
  TopoDS_Face best;
  double bestArea = 0;
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
    const TopoDS_Face& f = TopoDS::Face(ex.Current());
    BRepAdaptor_Surface s(f);
    if (s.GetType() != GeomAbs_Plane) continue;
    const gp_Pln pln = s.Plane();
    if (!pln.Axis().Direction().IsParallel(gp::DZ(), 1e-12) || !near(pln.Location().Z(), z)) continue;
    GProp_GProps props;
    BRepGProp::SurfaceProperties(f, props);
    if (props.Mass() > bestArea) {
      bestArea = props.Mass();
      best = f;
    }
  }
  if (best.IsNull()) fail("no planar face at z = " + std::to_string(z));
  return best;
}

void requireValid(const TopoDS_Shape& shape, const char* step) {
  if (shape.IsNull() || !BRepCheck_Analyzer(shape).IsValid()) fail(std::string("invalid shape after ") + step);
}

TopoDS_Shape cut(const TopoDS_Shape& from, const TopoDS_Shape& tool, const char* step) {
  BRepAlgoAPI_Cut op(from, tool);
  if (!op.IsDone() || op.HasErrors()) fail(std::string("boolean cut failed: ") + step);
  requireValid(op.Shape(), step);
  return op.Shape();
}

// The first paper's cylinder: diameter 100 mm, length 400 mm, axis z, centred at 0.
TopoDS_Shape makeCylinder() {
  return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -200), gp::DZ(), gp::DX()), 50, 400).Shape();
}

// A machined block 100 x 60 x 30 mm (x, y, z; z from 0 to 30, centred in x and y):
// filleted vertical edges, a pocket with filleted corners and floor, 10 through holes, a
// boss, chamfers on the top edges, the holes' top edges and the boss.
TopoDS_Shape makeBlock() {
  TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(-50, -30, 0), 100, 60, 30).Shape();

  {  // the four vertical edges, r 6
    BRepFilletAPI_MakeFillet fillet(block);
    for (const TopoDS_Edge& e : edgesWhere(block, [](const TopoDS_Edge& e) {
           const std::vector<gp_Pnt> p = samples(e);
           return near(p.front().X(), p.back().X()) && near(p.front().Y(), p.back().Y());
         }))
      fillet.Add(6, e);
    fillet.Build();
    if (!fillet.IsDone()) fail("fillet of the vertical edges failed");
    block = fillet.Shape();
    requireValid(block, "vertical fillets");
  }

  {  // pocket 40 x 30 x 10 mm, corners r 5
    TopoDS_Shape tool = BRepPrimAPI_MakeBox(gp_Pnt(-35, -15, 20), 40, 30, 11).Shape();
    BRepFilletAPI_MakeFillet fillet(tool);
    for (const TopoDS_Edge& e : edgesWhere(tool, [](const TopoDS_Edge& e) {
           const std::vector<gp_Pnt> p = samples(e);
           return near(p.front().X(), p.back().X()) && near(p.front().Y(), p.back().Y());
         }))
      fillet.Add(5, e);
    fillet.Build();
    if (!fillet.IsDone()) fail("fillet of the pocket corners failed");
    block = cut(block, fillet.Shape(), "pocket");
  }

  {  // pocket floor edges, r 2
    const TopoDS_Face floor = planarFaceAt(block, 20);
    BRepFilletAPI_MakeFillet fillet(block);
    for (const TopoDS_Edge& e : edgesWhere(floor, [](const TopoDS_Edge&) { return true; })) fillet.Add(2, e);
    fillet.Build();
    if (!fillet.IsDone()) fail("fillet of the pocket floor failed");
    block = fillet.Shape();
    requireValid(block, "pocket floor fillet");
  }

  {  // 10 through holes, diameter 5, in two rows along the long sides
    TopoDS_Compound holes;
    BRep_Builder builder;
    builder.MakeCompound(holes);
    for (double y : {-22.0, 22.0})
      for (double x : {-36.0, -18.0, 0.0, 18.0, 36.0})
        builder.Add(holes, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, y, -1), gp::DZ(), gp::DX()), 2.5, 32).Shape());
    block = cut(block, holes, "holes");
  }

  {  // boss, diameter 16, 10 high
    const TopoDS_Shape boss = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(25, 0, 30), gp::DZ(), gp::DX()), 8, 10).Shape();
    BRepAlgoAPI_Fuse fuse(block, boss);
    if (!fuse.IsDone() || fuse.HasErrors()) fail("boss fuse failed");
    block = fuse.Shape();
    requireValid(block, "boss");
  }

  {  // chamfers: the top face's outer loop 1.5 mm, the holes' top edges 0.5 mm, the boss 1 mm
    const TopoDS_Face top = planarFaceAt(block, 30);
    const TopoDS_Wire outer = BRepTools::OuterWire(top);
    BRepFilletAPI_MakeChamfer chamfer(block);
    for (const TopoDS_Edge& e : edgesWhere(outer, [](const TopoDS_Edge&) { return true; })) chamfer.Add(1.5, e);
    for (const TopoDS_Edge& e : edgesWhere(top, [](const TopoDS_Edge& e) { return isCircle(e, 2.5); }))
      chamfer.Add(0.5, e);
    for (const TopoDS_Edge& e : edgesWhere(block, [](const TopoDS_Edge& e) {
           return isCircle(e, 8) && allAt(e, [](const gp_Pnt& p) { return near(p.Z(), 40); });
         }))
      chamfer.Add(1, e);
    chamfer.Build();
    if (!chamfer.IsDone()) fail("chamfers failed");
    block = chamfer.Shape();
    requireValid(block, "chamfers");
  }
  return block;
}

// A freeform loft: five closed sections (circles and ellipses of different sizes, offset
// sideways) from z = 0 to 160 mm; one B-spline lateral face and two planar caps.
TopoDS_Shape makeLoft() {
  struct Section {
    double x, y, z, a, b;  // centre, semi-axes along x and y
  };
  const Section sections[] = {
      {0, 0, 0, 30, 30}, {8, 0, 40, 40, 28}, {15, 5, 80, 22, 22}, {8, 10, 120, 26, 34}, {0, 5, 160, 18, 18}};
  BRepOffsetAPI_ThruSections loft(/*isSolid=*/true, /*ruled=*/false);
  for (const Section& s : sections) {
    // Every section starts at its +x point and runs counter-clockwise about +z: no twist.
    const gp_Pnt c(s.x, s.y, s.z);
    TopoDS_Edge edge;
    if (s.a == s.b)
      edge = BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(c, gp::DZ(), gp::DX()), s.a)).Edge();
    else if (s.a > s.b)
      edge = BRepBuilderAPI_MakeEdge(gp_Elips(gp_Ax2(c, gp::DZ(), gp::DX()), s.a, s.b)).Edge();
    else  // major axis along y: the ellipse's parameter 0 lies on +y, start it at -pi/2 (+x)
      edge = BRepBuilderAPI_MakeEdge(gp_Elips(gp_Ax2(c, gp::DZ(), gp::DY()), s.b, s.a), -std::numbers::pi / 2, 1.5 * std::numbers::pi).Edge();
    loft.AddWire(BRepBuilderAPI_MakeWire(edge).Wire());
  }
  loft.CheckCompatibility(false);
  loft.Build();
  if (!loft.IsDone()) fail("loft failed");
  requireValid(loft.Shape(), "loft");
  return loft.Shape();
}

// A perforated plate 200 x 200 x 5 mm with a 32 x 32 grid of 3 mm through holes, pitch
// 6.25 mm, cut in one boolean operation.
TopoDS_Shape makePlate() {
  const TopoDS_Shape plate = BRepPrimAPI_MakeBox(gp_Pnt(-100, -100, 0), 200, 200, 5).Shape();
  TopoDS_Compound holes;
  BRep_Builder builder;
  builder.MakeCompound(holes);
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      builder.Add(holes, BRepPrimAPI_MakeCylinder(
                             gp_Ax2(gp_Pnt(-96.875 + 6.25 * i, -96.875 + 6.25 * j, -1), gp::DZ(), gp::DX()), 1.5, 7)
                             .Shape());
  return cut(plate, holes, "plate holes");
}

struct Part {
  std::string name;
  std::function<TopoDS_Shape()> make;
  const char* massKey;  // "mass_kg" or "density_kg_m3"
  double massValue;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_sample_parts <directory>\n"
                 "Writes cylinder, block, loft and plate .brep (mm) and parts.json into <directory>.\n";
    return 2;
  }
  const fs::path dir = argv[1];
  const std::vector<Part> parts = {
      {"cylinder", makeCylinder, "mass_kg", 2.0},
      {"block", makeBlock, "density_kg_m3", 2700},
      {"loft", makeLoft, "density_kg_m3", 1200},
      {"plate", makePlate, "density_kg_m3", 7850},
  };
  try {
    fs::create_directories(dir);
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    std::printf("%-9s %7s %7s %8s %10s %9s %9s\n", "part", "faces", "edges", "vertices", "bytes", "build s", "check s");
    for (const Part& part : parts) {
      const auto t0 = std::chrono::steady_clock::now();
      const TopoDS_Shape shape = part.make();
      requireValid(shape, part.name.c_str());
      const auto t1 = std::chrono::steady_clock::now();
      const std::string file = part.name + ".brep";
      const fs::path path = dir / file;
      // Version 1, no triangulation: the smallest and most widely readable text.
      if (!BRepTools::Write(shape, path.c_str(), false, false, TopTools_FormatVersion_VERSION_1))
        fail("could not write " + path.string());
      // Read back as every user of the part will: validated, in millimetres.
      const hg::geometry::PartModelPtr model = hg::geometry::PartModel::fromFile(path, hg::geometry::LengthUnit::Millimetre);
      const auto t2 = std::chrono::steady_clock::now();
      const int faces = model->faces().Extent();
      std::printf("%-9s %7d %7d %8d %10ju %9.2f %9.2f\n", part.name.c_str(), faces, model->edges().Extent(),
                  model->vertices().Extent(), static_cast<std::uintmax_t>(fs::file_size(path)),
                  std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count());
      for (const std::string& w : model->warnings()) std::printf("  warning: %s\n", w.c_str());
      nlohmann::ordered_json entry;
      entry["name"] = part.name;
      entry["file"] = file;
      entry["unit"] = "mm";
      entry["faces"] = faces;
      entry[part.massKey] = part.massValue;
      list.push_back(entry);
    }
    std::ofstream out(dir / "parts.json");
    out << list.dump(2) << '\n';
    if (!out) fail("could not write parts.json");
  } catch (const Standard_Failure& e) {
    std::cerr << "make_sample_parts: OpenCASCADE: " << e.GetMessageString() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "make_sample_parts: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
