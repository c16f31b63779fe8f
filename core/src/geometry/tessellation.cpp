#include "hapticgrasp/geometry/tessellation.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepMesh_Triangulator.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GCPnts_TangentialDeflection.hxx>
#include <Poly_PolygonOnTriangulation.hxx>
#include <Poly_Triangulation.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_SequenceOfInteger.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Ax3.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_map>
#include <vector>

#include "curve_on_face.hpp"
#include "meshing_limits.hpp"
#include "loop_crossings.hpp"

namespace hg::geometry {
namespace {

// How long BRepMesh may work on a damaged part's mesh (MeshingDeadline): within the 10 s
// in which every input gets its result or one line.
constexpr double kDamagedMeshingSeconds = 5;

// Welds nodes that lie within `tolerance` of each other (faces duplicate the nodes they
// share along an edge, and a periodic face duplicates its seam).
class Welder {
 public:
  Welder(std::vector<Vec3>& vertices, double tolerance) : vertices_(vertices), cell_(tolerance) {}

  int add(const Vec3& p) {
    const Key k = key(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = map_.find({k.x + dx, k.y + dy, k.z + dz});
          if (it != map_.end() && (vertices_[it->second] - p).norm() <= cell_) return it->second;
        }
    const int index = static_cast<int>(vertices_.size());
    vertices_.push_back(p);
    map_.emplace(k, index);
    return index;
  }

 private:
  struct Key {
    long long x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      // Unsigned: the products wrap, as a hash may (signed ones would overflow).
      const auto u = [](long long v) { return static_cast<unsigned long long>(v); };
      return std::hash<unsigned long long>()(u(k.x) * 73856093ULL ^ u(k.y) * 19349663ULL ^ u(k.z) * 83492791ULL);
    }
  };
  // A damaged surface can put a node at NaN or far beyond any part (fuzzing found one): a
  // cell number past 2^60 would overflow the key's arithmetic, so such a mesh is refused.
  Key key(const Vec3& p) const {
    const Vec3 cells = p / cell_;
    if (!(cells.cwiseAbs().maxCoeff() < 0x1p60)) {
      char where[96];
      std::snprintf(where, sizeof where, "(%.3g, %.3g, %.3g) m", p.x(), p.y(), p.z());
      throw GeometryError(std::string("the mesh has a node at ") + where + ": its surfaces run away");
    }
    return {std::llround(cells.x()), std::llround(cells.y()), std::llround(cells.z())};
  }
  std::vector<Vec3>& vertices_;
  double cell_;
  std::unordered_map<Key, int, Hash> map_;
};

// The points of an edge as the meshed faces around it discretized it (so that a face filled
// below meets them node for node), in the edge's own direction; or, when no face has, as
// GCPnts discretizes it.
std::vector<gp_Pnt> edgePoints(const TopoDS_Edge& edge, double deflection) {
  Handle(Poly_PolygonOnTriangulation) polygon;
  Handle(Poly_Triangulation) mesh;
  TopLoc_Location location;
  BRep_Tool::PolygonOnTriangulation(edge, polygon, mesh, location);
  std::vector<gp_Pnt> points;
  if (!polygon.IsNull() && !mesh.IsNull()) {
    const gp_Trsf trsf = location.Transformation();
    for (int i = 1; i <= polygon->NbNodes(); ++i) points.push_back(mesh->Node(polygon->Node(i)).Transformed(trsf));
    return points;
  }
  const BRepAdaptor_Curve curve(edge);
  const GCPnts_TangentialDeflection discrete(curve, 0.3, deflection);
  for (int i = 1; i <= discrete.NbPoints(); ++i) points.push_back(discrete.Value(i));
  return points;
}

using Triangle = std::array<gp_Pnt, 3>;

// Newell: the area vector of a closed polyline (its normal times its area, for a planar one).
gp_XYZ areaVector(const Polyline& loop) {
  gp_XYZ sum(0, 0, 0);
  for (std::size_t k = 0; k < loop.size(); ++k) sum += loop[k].Crossed(loop[(k + 1) % loop.size()]);
  return sum * 0.5;
}

// Whether p lies inside a closed polyline, seen along `normal` (even-odd crossings of a ray
// in the plane).
bool encloses(const Polyline& loop, const gp_XYZ& p, const gp_Dir& normal) {
  const gp_Ax3 frame(gp_Pnt(0, 0, 0), normal);
  const gp_XYZ ex = frame.XDirection().XYZ(), ey = frame.YDirection().XYZ();
  const double px = p.Dot(ex), py = p.Dot(ey);
  bool in = false;
  for (std::size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const double xi = loop[i].Dot(ex), yi = loop[i].Dot(ey), xj = loop[j].Dot(ex), yj = loop[j].Dot(ey);
    if ((yi > py) != (yj > py) && px < xi + (py - yi) / (yj - yi) * (xj - xi)) in = !in;
  }
  return in;
}

// Triangles over a region: an outline running counter-clockwise about `up` and the holes
// inside it running the other way, each triangle facing `up`. BRepMesh_Triangulator
// first; if it fails, a fan from the middle of the outline over every loop, each triangle
// turned as its loop runs: whatever the loops' shape, a chain whose boundary is the loops.
std::vector<Triangle> triangulate(const std::vector<const Polyline*>& loops, const gp_Dir& up) {
  NCollection_Vector<gp_XYZ> points;
  NCollection_List<TColStd_SequenceOfInteger> wires;
  for (const Polyline* loop : loops) {
    TColStd_SequenceOfInteger wire;
    for (const gp_XYZ& p : *loop) {
      wire.Append(points.Length());
      points.Append(p);
    }
    wires.Append(wire);
  }
  std::vector<Triangle> triangles;
  NCollection_List<Poly_Triangle> found;
  bool done = false;
  try {
    BRepMesh_Triangulator triangulator(points, wires, up);
    done = triangulator.Perform(found);
  } catch (const Standard_Failure&) {
    done = false;
  }
  if (done) {
    for (const Poly_Triangle& t : found) {
      int a, b, c;
      t.Get(a, b, c);  // 1-based
      Triangle triangle{gp_Pnt(points(a - 1)), gp_Pnt(points(b - 1)), gp_Pnt(points(c - 1))};
      if (gp_Vec(triangle[0], triangle[1]).Crossed(gp_Vec(triangle[0], triangle[2])).Dot(gp_Vec(up)) < 0)
        std::swap(triangle[1], triangle[2]);
      triangles.push_back(triangle);
    }
    return triangles;
  }
  gp_XYZ centre(0, 0, 0);
  for (const gp_XYZ& p : *loops.front()) centre += p;
  const gp_Pnt middle(centre / static_cast<double>(loops.front()->size()));
  for (const Polyline* loop : loops)
    for (std::size_t k = 0; k < loop->size(); ++k)
      triangles.push_back({middle, gp_Pnt((*loop)[k]), gp_Pnt((*loop)[(k + 1) % loop->size()])});
  return triangles;
}

// Triangles for a face BRepMesh left without any (a self-intersecting wire, a broken
// pcurve): its boundary, as its neighbours discretized it, triangulated in the plane of its
// outline and turned the way the face faces. Without them the mesh would have a hole there,
// and points near the hole would take their sign from faces across it.
//
// A wire that crosses itself means the region where its planar winding number is not 0,
// counted with that number (the part's winding number counts the face so): it is cut at
// its crossings into loops that do not cross. Each loop that runs the face's way is
// filled, less the loops running the other way inside it (holes, or where a lobe cancels
// it); a loop running the other way inside none is a lobe turned over, filled facing
// inwards. So the fill covers the region and no more (a fan would also cover, twice and
// cancelling, corners the wire cuts off: too close a foot for points near them).
std::vector<Triangle> fillFace(const TopoDS_Face& face, double deflection) {
  std::vector<Polyline> wires;
  gp_XYZ normal(0, 0, 0);
  for (TopExp_Explorer w(face, TopAbs_WIRE); w.More(); w.Next()) {
    Polyline loop;
    for (BRepTools_WireExplorer e(TopoDS::Wire(w.Current()), face); e.More(); e.Next()) {
      std::vector<gp_Pnt> along = edgePoints(e.Current(), deflection);
      if (e.Current().Orientation() == TopAbs_REVERSED) std::reverse(along.begin(), along.end());
      for (std::size_t k = 0; k + 1 < along.size(); ++k) loop.push_back(along[k].XYZ());  // the last point starts the next edge
    }
    if (loop.size() < 3) continue;
    normal += areaVector(loop);
    wires.push_back(std::move(loop));
  }
  if (wires.empty() || normal.Modulus() <= 0) return {};
  const gp_Dir outward(normal);

  std::vector<Polyline> loops;
  bool crossed = false;
  for (const Polyline& wire : wires) {
    std::vector<Polyline> cut = cutAtCrossings(wire, outward);
    crossed |= cut.size() > 1;
    for (Polyline& loop : cut) loops.push_back(std::move(loop));
  }
  if (!crossed) {  // the outline and its holes, as BRepCheck expects them
    std::vector<const Polyline*> all;
    for (const Polyline& wire : wires) all.push_back(&wire);
    return triangulate(all, outward);
  }

  std::vector<const Polyline*> along, against;
  for (const Polyline& loop : loops) (areaVector(loop).Dot(outward.XYZ()) > 0 ? along : against).push_back(&loop);
  std::vector<std::vector<const Polyline*>> regions;
  for (const Polyline* loop : along) regions.push_back({loop});
  std::vector<Triangle> triangles;
  for (const Polyline* loop : against) {
    // A point surely inside the loop: the middle of its own largest triangle.
    const std::vector<Triangle> own = triangulate({loop}, outward.Reversed());
    const Triangle* largest = nullptr;
    double area = 0;
    for (const Triangle& t : own) {
      const double a = gp_Vec(t[0], t[1]).Crossed(gp_Vec(t[0], t[2])).Magnitude();
      if (a > area) area = a, largest = &t;
    }
    std::vector<const Polyline*>* region = nullptr;  // the innermost that encloses it
    double regionArea = 0;
    if (largest) {
      const gp_XYZ inner = (largest->at(0).XYZ() + largest->at(1).XYZ() + largest->at(2).XYZ()) / 3;
      for (auto& r : regions) {
        const double rArea = areaVector(*r.front()).Modulus();
        if ((!region || rArea < regionArea) && encloses(*r.front(), inner, outward)) region = &r, regionArea = rArea;
      }
    }
    if (region) region->push_back(loop);  // a hole of that region
    else triangles.insert(triangles.end(), own.begin(), own.end());  // a lobe turned over
  }
  for (const auto& region : regions) {
    const std::vector<Triangle> filled = triangulate(region, outward);
    triangles.insert(triangles.end(), filled.begin(), filled.end());
  }
  return triangles;
}

// BRepMesh on `shape` (meshWithin: a face whose grid of nodes would pass its limit is left
// without triangles, and filled from its edges as others BRepMesh fails on are). A damaged
// part's mesh stops at a deadline (MeshingDeadline): a loft with a few digits lost in its
// poles, its edges within 0.0001 mm of its faces, kept BRepMesh busy at 0.01 mm for more
// than 30 s and 2 GB (fuzz_brep_backend), where the sound loft takes 3.8 s. Then it throws,
// in one line.
bool mesh(const TopoDS_Shape& shape, double deflection, double angularDeflection_rad, bool damaged) {
  const MeshingParameters parameters{deflection, angularDeflection_rad};
  if (!damaged) return meshWithin(shape, parameters, Handle(Message_ProgressIndicator)()).done;
  const Handle(MeshingDeadline) deadline = new MeshingDeadline(kDamagedMeshingSeconds);
  const bool done = meshWithin(shape, parameters, deadline).done;
  if (deadline->passed())
    throw GeometryError("meshing the damaged part did not finish within " +
                        std::to_string(static_cast<int>(kDamagedMeshingSeconds)) + " s");
  return done;
}

// BRepMesh on the copy (`copier`'s shape), but for the curved faces of a damaged part whose
// edges stray from them by more than kMaxEdgeStray of its size: with the face's parameters
// contradicting its edges, BRepMesh at a fine deflection ran for minutes (a cone whose
// bottom circle ran diagonally across it; fuzz inputs). Those are filled from their edges
// instead, as faces BRepMesh leaves without triangles are. A sound part's edges lie within
// their tolerances, and its faces are not looked at. Returns whether BRepMesh says it is
// done.
bool meshFacesOnTheirEdges(const PartModel& part, const BRepBuilderAPI_Copy& copier, const TopoDS_Shape& copy,
                           double deflection, double angularDeflection_rad) {
  std::vector<FaceOffItsEdges> off;
  const bool damaged = part.backendChoice().backend != Backend::Exact;
  if (damaged)
    off = curvedFacesOffTheirEdges(part.shape(), kMaxEdgeStray * part.characteristicLength() / part.metresPerUnit());
  if (off.empty()) return mesh(copy, deflection, angularDeflection_rad, damaged);
  TopoDS_Compound faces;
  BRep_Builder builder;
  builder.MakeCompound(faces);
  const TopTools_IndexedMapOfShape& all = part.faces();
  for (int f = 1, k = 0; f <= all.Extent(); ++f) {
    if (k < static_cast<int>(off.size()) && off[k].face == f) {
      ++k;
      continue;
    }
    builder.Add(faces, copier.ModifiedShape(all(f)));
  }
  return mesh(faces, deflection, angularDeflection_rad, damaged);
}

}  // namespace

double Tessellation::area() const {
  double a = 0;
  for (const auto& t : triangles)
    a += 0.5 * (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).norm();
  return a;
}

Tessellation tessellate(const PartModel& part, double deflection_m, double angularDeflection_rad) {
  if (!(deflection_m > 0)) throw GeometryError("tessellation deflection must be positive");
  const double s = part.metresPerUnit();
  // Mesh a copy: BRepMesh stores triangulations inside the faces of the shape it is given,
  // and the part's shape is shared read-only.
  BRepBuilderAPI_Copy copier(part.shape(), true, false);
  TopoDS_Shape shape = copier.Shape();
  BRepTools::Clean(shape);
  if (!meshFacesOnTheirEdges(part, copier, shape, deflection_m / s, angularDeflection_rad))
    throw GeometryError("tessellation failed");

  Tessellation mesh;
  mesh.deflection_m = deflection_m;
  Welder welder(mesh.vertices, 1e-9 * part.characteristicLength());
  const TopTools_IndexedMapOfShape& faces = part.faces();
  for (int f = 1; f <= faces.Extent(); ++f) {
    const TopoDS_Face& original = TopoDS::Face(faces(f));
    const TopoDS_Face face = TopoDS::Face(copier.ModifiedShape(original));
    TopLoc_Location location;
    const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, location);
    if (tri.IsNull() || tri->NbTriangles() == 0) {
      // Oriented as the original is in the solid: its wires then run around its outward side.
      const std::vector<std::array<gp_Pnt, 3>> filled =
          fillFace(TopoDS::Face(face.Oriented(original.Orientation())), deflection_m / s);
      if (filled.empty()) throw GeometryError("tessellation left face " + std::to_string(f) + " without triangles");
      for (const auto& t : filled) {
        Eigen::Vector3i corners;
        for (int k = 0; k < 3; ++k) corners[k] = welder.add(Vec3(t[k].X(), t[k].Y(), t[k].Z()) * s);
        if (corners[0] == corners[1] || corners[1] == corners[2] || corners[0] == corners[2]) continue;
        mesh.triangles.push_back(corners);
        mesh.triangleFace.push_back(f);
      }
      mesh.filledFaces.push_back(f);
      continue;
    }
    const gp_Trsf trsf = location.Transformation();
    std::vector<int> node(tri->NbNodes() + 1);
    for (int i = 1; i <= tri->NbNodes(); ++i) {
      const gp_Pnt p = tri->Node(i).Transformed(trsf);
      node[i] = welder.add(Vec3(p.X(), p.Y(), p.Z()) * s);
    }
    // TopExp::MapShapes stored the face with its orientation in the solid: it decides the winding.
    const bool reversed = original.Orientation() == TopAbs_REVERSED;
    for (int i = 1; i <= tri->NbTriangles(); ++i) {
      int a, b, c;
      tri->Triangle(i).Get(a, b, c);
      if (reversed) std::swap(b, c);
      const Eigen::Vector3i t(node[a], node[b], node[c]);
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;  // collapsed by welding
      mesh.triangles.push_back(t);
      mesh.triangleFace.push_back(f);
    }
  }
  for (const Vec3& v : mesh.vertices) mesh.bounds.extend(v);
  return mesh;
}

}  // namespace hg::geometry
