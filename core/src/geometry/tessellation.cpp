#include "hapticgrasp/geometry/tessellation.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepMesh_Triangulator.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <GCPnts_TangentialDeflection.hxx>
#include <Poly_PolygonOnTriangulation.hxx>
#include <Poly_Triangulation.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_SequenceOfInteger.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Wire.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <vector>

namespace hg::geometry {
namespace {

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
      return std::hash<long long>()(k.x * 73856093LL ^ k.y * 19349663LL ^ k.z * 83492791LL);
    }
  };
  Key key(const Vec3& p) const {
    return {std::llround(p.x() / cell_), std::llround(p.y() / cell_), std::llround(p.z() / cell_)};
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

// Triangles for a face BRepMesh left without any (a self-intersecting wire, a broken
// pcurve): its boundary, as its neighbours discretized it, triangulated in the plane of its
// outline and turned the way the face faces. Without them the mesh would have a hole there,
// and points near the hole would take their sign from faces across it.
std::vector<std::array<gp_Pnt, 3>> fillFace(const TopoDS_Face& face, double deflection) {
  NCollection_Vector<gp_XYZ> points;
  NCollection_List<TColStd_SequenceOfInteger> wires;
  gp_XYZ normal(0, 0, 0), centre(0, 0, 0);
  for (TopExp_Explorer w(face, TopAbs_WIRE); w.More(); w.Next()) {
    TColStd_SequenceOfInteger loop;
    for (BRepTools_WireExplorer e(TopoDS::Wire(w.Current()), face); e.More(); e.Next()) {
      std::vector<gp_Pnt> along = edgePoints(e.Current(), deflection);
      if (e.Current().Orientation() == TopAbs_REVERSED) std::reverse(along.begin(), along.end());
      for (std::size_t k = 0; k + 1 < along.size(); ++k) {  // the last point starts the next edge
        loop.Append(points.Length());
        points.Append(along[k].XYZ());
      }
    }
    if (loop.Length() < 3) continue;
    for (int k = 1; k <= loop.Length(); ++k) {  // Newell: the loop's area vector
      const gp_XYZ& a = points(loop(k));
      const gp_XYZ& b = points(loop(k % loop.Length() + 1));
      normal += a.Crossed(b);
      centre += a;
    }
    wires.Append(loop);
  }
  std::vector<std::array<gp_Pnt, 3>> triangles;
  if (wires.IsEmpty() || normal.Modulus() <= 0) return triangles;
  const gp_Dir outward(normal);
  NCollection_List<Poly_Triangle> found;
  bool done = false;
  try {
    BRepMesh_Triangulator triangulator(points, wires, outward);
    done = triangulator.Perform(found);
  } catch (const Standard_Failure&) {
    done = false;
  }
  if (done) {
    for (const Poly_Triangle& t : found) {
      int a, b, c;
      t.Get(a, b, c);
      triangles.push_back({gp_Pnt(points(a - 1)), gp_Pnt(points(b - 1)), gp_Pnt(points(c - 1))});
    }
  } else {
    // A fan from the centre of the boundary: closed along the boundary, whatever its shape.
    int count = 0;
    for (const TColStd_SequenceOfInteger& loop : wires) count += loop.Length();
    const gp_Pnt middle(centre / count);
    for (const TColStd_SequenceOfInteger& loop : wires)
      for (int k = 1; k <= loop.Length(); ++k)
        triangles.push_back({middle, gp_Pnt(points(loop(k))), gp_Pnt(points(loop(k % loop.Length() + 1)))});
  }
  for (auto& t : triangles)
    if (gp_Vec(t[0], t[1]).Crossed(gp_Vec(t[0], t[2])).Dot(gp_Vec(outward)) < 0) std::swap(t[1], t[2]);
  return triangles;
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
  BRepMesh_IncrementalMesh mesher(shape, deflection_m / s, false, angularDeflection_rad, false);
  if (!mesher.IsDone()) throw GeometryError("tessellation failed");

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
