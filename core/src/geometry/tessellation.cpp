#include "hapticgrasp/geometry/tessellation.hpp"

#include <BRepBuilderAPI_Copy.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>

#include <cmath>
#include <unordered_map>

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
    if (tri.IsNull()) throw GeometryError("tessellation left face " + std::to_string(f) + " without triangles");
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
