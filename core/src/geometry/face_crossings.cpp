#include "hapticgrasp/geometry/face_crossings.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <ElSLib.hxx>
#include <GCPnts_TangentialDeflection.hxx>
#include <Geom_Surface.hxx>
#include <Poly_Triangulation.hxx>
#include <Precision.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_Lin.hxx>
#include <gp_Pln.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

#include "curve_on_face.hpp"
#include "meshing_limits.hpp"

namespace hg::geometry {
namespace {

// The search mesh: coarse (1 % of the shape's size, and at most 1 rad per segment), since
// every candidate is confirmed on the exact surfaces; finer meshes only cost time (the
// sample plate's 1024 holes: 0.23 s at 1 rad, 0.33 s at 0.5 rad).
constexpr double kRelativeDeflection = 0.01;
constexpr double kAngularDeflection = 1.0;
// Planar faces' boundaries are discretized ten times finer, at most 0.5 rad per segment: a
// point that near a boundary is not classified.
constexpr double kBoundaryDeflection = 0.1;
constexpr double kBoundaryAngle = 0.5;
// Bounds on the exact work: candidates kept per pair of faces, pairs of faces confirmed,
// confirmations in all (each a few projections onto the surfaces; touching pairs such as a
// bolt in its hole yield many candidates, each rejected at its first step).
constexpr int kCandidatesPerPair = 6;
constexpr int kMaxPairs = 200;
constexpr int kMaxConfirmations = 500;
// Surfaces that meet at less than ~1.1 degrees touch (coincident or tangent faces) rather
// than cross.
constexpr double kMinSine = 0.02;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Box3 {
  std::array<double, 3> lo{kInfinity, kInfinity, kInfinity}, hi{-kInfinity, -kInfinity, -kInfinity};
  void add(const gp_XYZ& p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p.Coord(k + 1));
      hi[k] = std::max(hi[k], p.Coord(k + 1));
    }
  }
  void add(const Box3& b) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], b.lo[k]);
      hi[k] = std::max(hi[k], b.hi[k]);
    }
  }
  void enlarge(double d) {
    for (int k = 0; k < 3; ++k) {
      lo[k] -= d;
      hi[k] += d;
    }
  }
  bool overlaps(const Box3& b) const {
    for (int k = 0; k < 3; ++k)
      if (lo[k] > b.hi[k] || b.lo[k] > hi[k]) return false;
    return true;
  }
  double centre(int k) const { return (lo[k] + hi[k]) / 2; }
  int longestAxis() const {
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    return axis;
  }
};

Box3 toBox3(const Bnd_Box& box) {
  Box3 b;
  if (box.IsVoid()) return b;
  box.Get(b.lo[0], b.lo[1], b.lo[2], b.hi[0], b.hi[1], b.hi[2]);
  return b;
}

struct Triangle {
  int face = 0;
  std::array<gp_XYZ, 3> p;
  std::array<gp_XY, 3> uv;
  bool hasUV = false;
};

// A triangle of a curved face, or a whole planar face (triangle < 0).
struct Primitive {
  Box3 box;
  int face = 0;
  int triangle = -1;
};

// A bounding-volume hierarchy over the primitives, for the pairs whose boxes overlap.
class Bvh {
 public:
  explicit Bvh(std::vector<Primitive>& primitives) : primitives_(primitives) {
    if (primitives_.empty()) return;
    nodes_.reserve(2 * primitives_.size());
    build(0, static_cast<int>(primitives_.size()));
  }

  // Calls visit(a, b) for each pair whose boxes overlap while it returns true; false if it
  // stopped the walk.
  template <class Visit>
  bool forEachOverlappingPair(Visit&& visit) const {
    return nodes_.empty() || self(0, visit);
  }

 private:
  struct Node {
    Box3 box;
    int left = -1, right = -1;  // children; leaves have none
    int first = 0, count = 0;   // a leaf's primitives
  };
  static constexpr int kLeafSize = 4;

  int build(int first, int count) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    Box3 box;
    for (int i = first; i < first + count; ++i) box.add(primitives_[i].box);
    nodes_[index].box = box;
    if (count <= kLeafSize) {
      nodes_[index].first = first;
      nodes_[index].count = count;
      return index;
    }
    const int axis = box.longestAxis();
    const auto begin = primitives_.begin() + first;
    std::nth_element(begin, begin + count / 2, begin + count, [axis](const Primitive& a, const Primitive& b) {
      return a.box.centre(axis) < b.box.centre(axis);
    });
    const int left = build(first, count / 2);
    const int right = build(first + count / 2, count - count / 2);
    nodes_[index].left = left;
    nodes_[index].right = right;
    return index;
  }

  template <class Visit>
  bool self(int n, Visit& visit) const {
    const Node& node = nodes_[n];
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i)
        for (int j = i + 1; j < node.first + node.count; ++j)
          if (primitives_[i].box.overlaps(primitives_[j].box) && !visit(primitives_[i], primitives_[j])) return false;
      return true;
    }
    return self(node.left, visit) && self(node.right, visit) && pair(node.left, node.right, visit);
  }

  template <class Visit>
  bool pair(int a, int b, Visit& visit) const {
    const Node& na = nodes_[a];
    const Node& nb = nodes_[b];
    if (!na.box.overlaps(nb.box)) return true;
    if (na.left < 0 && nb.left < 0) {
      for (int i = na.first; i < na.first + na.count; ++i)
        for (int j = nb.first; j < nb.first + nb.count; ++j)
          if (primitives_[i].box.overlaps(primitives_[j].box) && !visit(primitives_[i], primitives_[j])) return false;
      return true;
    }
    // Descend the larger node (or the one that is not a leaf).
    const bool splitA = nb.left < 0 || (na.left >= 0 && volume(na.box) >= volume(nb.box));
    if (splitA) return pair(na.left, b, visit) && pair(na.right, b, visit);
    return pair(a, nb.left, visit) && pair(a, nb.right, visit);
  }

  static double volume(const Box3& b) { return (b.hi[0] - b.lo[0]) * (b.hi[1] - b.lo[1]) * (b.hi[2] - b.lo[2]); }

  std::vector<Primitive>& primitives_;
  std::vector<Node> nodes_;
};

// Where a triangle meets a plane it straddles: the two points where its edges (or a corner
// on the plane) cross it. `d`: the corners' signed distances to the plane.
std::array<gp_XYZ, 2> sectionOnPlane(const std::array<gp_XYZ, 3>& p, const std::array<double, 3>& d) {
  std::array<gp_XYZ, 2> out;
  int n = 0;
  for (int i = 0; i < 3 && n < 2; ++i) {
    const int j = (i + 1) % 3;
    if (d[i] == 0) out[n++] = p[i];
    if (n < 2 && ((d[i] > 0 && d[j] < 0) || (d[i] < 0 && d[j] > 0)))
      out[n++] = p[i] + (p[j] - p[i]) * (d[i] / (d[i] - d[j]));
  }
  if (n < 2) out[1] = out[0];
  return out;
}

bool straddles(const std::array<double, 3>& d, double eps) {
  return std::max({d[0], d[1], d[2]}) > eps && std::min({d[0], d[1], d[2]}) < -eps;
}

std::optional<gp_XYZ> unitNormal(const std::array<gp_XYZ, 3>& p) {
  const gp_XYZ n = (p[1] - p[0]).Crossed(p[2] - p[0]);
  const double length = n.Modulus();
  const double scale = std::max({(p[1] - p[0]).SquareModulus(), (p[2] - p[0]).SquareModulus(), (p[2] - p[1]).SquareModulus()});
  if (!(length > 1e-12 * scale)) return std::nullopt;  // a sliver has no plane
  return n / length;
}

// Where two triangles cross: each has corners strictly (beyond eps) on both sides of the
// other's plane, and their sections on the line where the planes meet overlap by more than
// eps. Triangles that share an edge never do; triangles that share a corner only if they
// fold through each other.
std::optional<gp_XYZ> trianglesCross(const std::array<gp_XYZ, 3>& a, const std::array<gp_XYZ, 3>& b, double eps) {
  const auto na = unitNormal(a), nb = unitNormal(b);
  if (!na || !nb) return std::nullopt;
  std::array<double, 3> da, db;
  for (int i = 0; i < 3; ++i) {
    da[i] = (a[i] - b[0]).Dot(*nb);
    db[i] = (b[i] - a[0]).Dot(*na);
  }
  if (!straddles(da, eps) || !straddles(db, eps)) return std::nullopt;
  gp_XYZ direction = na->Crossed(*nb);
  if (direction.Modulus() < 1e-12) return std::nullopt;
  direction.Normalize();
  const auto sa = sectionOnPlane(a, da), sb = sectionOnPlane(b, db);
  double a0 = sa[0].Dot(direction), a1 = sa[1].Dot(direction);
  double b0 = sb[0].Dot(direction), b1 = sb[1].Dot(direction);
  if (a0 > a1) std::swap(a0, a1);
  if (b0 > b1) std::swap(b0, b1);
  const double lo = std::max(a0, b0), hi = std::min(a1, b1);
  if (!(hi - lo > eps)) return std::nullopt;
  // The middle of the overlap, on a's section.
  const double t = (lo + hi) / 2;
  const double s0 = sa[0].Dot(direction), s1 = sa[1].Dot(direction);
  const double u = std::abs(s1 - s0) > 0 ? (t - s0) / (s1 - s0) : 0.5;
  return sa[0] + (sa[1] - sa[0]) * u;
}

// Barycentric (u, v) of a point on a triangle, interpolated.
gp_XY interpolateUV(const Triangle& t, const gp_XYZ& q) {
  const gp_XYZ e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0], r = q - t.p[0];
  const double d11 = e1.Dot(e1), d12 = e1.Dot(e2), d22 = e2.Dot(e2), r1 = r.Dot(e1), r2 = r.Dot(e2);
  const double det = d11 * d22 - d12 * d12;
  if (!(std::abs(det) > 0)) return t.uv[0];
  const double b1 = (d22 * r1 - d12 * r2) / det, b2 = (d11 * r2 - d12 * r1) / det;
  return t.uv[0] + (t.uv[1] - t.uv[0]) * b1 + (t.uv[2] - t.uv[0]) * b2;
}

// A point where two faces may cross, with where it lies on each face when known.
struct Candidate {
  gp_XYZ point;
  std::array<std::optional<gp_XY>, 2> uv;
};

// A planar face as its boundary polylines in the plane's (u, v), which are lengths: to
// classify points, and to find where a line runs inside the face. A point nearer the boundary
// than the polylines' deflection plus a margin is "near": no classification is trusted
// there, and it is where faces touch (a bolt in its hole) rather than cross.
class PlanarRegion {
 public:
  enum class Where { In, Out, Near };

  PlanarRegion(const TopoDS_Face& face, const gp_Pln& plane, double deflection) : plane_(plane), deflection_(deflection) {
    for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More(); ex.Next()) {
      const TopoDS_Edge& edge = TopoDS::Edge(ex.Current());
      if (BRep_Tool::Degenerated(edge)) continue;
      std::vector<gp_XYZ> line;
      const BRepAdaptor_Curve curve(edge);
      if (curve.GetType() == GeomAbs_Line) {
        line = {curve.Value(curve.FirstParameter()).XYZ(), curve.Value(curve.LastParameter()).XYZ()};
      } else {
        const GCPnts_TangentialDeflection points(curve, kBoundaryAngle, deflection);
        for (int k = 1; k <= points.NbPoints(); ++k) line.push_back(points.Value(k).XYZ());
      }
      Flat& flat = flats_.emplace_back();
      for (const gp_XYZ& p : line) {
        flat.points.push_back(uvOf(p));
        flat.lo.SetX(std::min(flat.lo.X(), flat.points.back().X()));
        flat.lo.SetY(std::min(flat.lo.Y(), flat.points.back().Y()));
        flat.hi.SetX(std::max(flat.hi.X(), flat.points.back().X()));
        flat.hi.SetY(std::max(flat.hi.Y(), flat.points.back().Y()));
      }
    }
  }

  // Where a line of the plane runs inside the face, as parameter intervals along it, each
  // shortened at both ends by the boundary band (what remains is clear of the boundary).
  std::vector<std::pair<double, double>> spansAlong(const gp_Lin& line, double margin) const {
    const gp_XY o = uvOf(line.Location().XYZ());
    const gp_XY d = uvOf(line.Location().XYZ() + line.Direction().XYZ()) - o;  // unit: the plane's (u, v) are lengths
    std::vector<double> crossings;
    for (const Flat& flat : flats_)
      for (std::size_t k = 0; k + 1 < flat.points.size(); ++k) {
        const gp_XY a = flat.points[k] - o, b = flat.points[k + 1] - o;
        const double sa = d.Crossed(a), sb = d.Crossed(b);  // sides of the line, >= 0 counted as one side
        if ((sa >= 0) == (sb >= 0)) continue;
        const gp_XY x = a + (b - a) * (sa / (sa - sb));
        crossings.push_back(x.Dot(d));
      }
    std::sort(crossings.begin(), crossings.end());
    std::vector<std::pair<double, double>> spans;
    const double band = deflection_ + margin;
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2)
      if (crossings[k + 1] - crossings[k] > 2 * band) spans.emplace_back(crossings[k] + band, crossings[k + 1] - band);
    return spans;
  }

  // Ray casting along +u over every edge's polyline (the edges close into loops); the
  // polylines whose boxes hold the point tell whether it is near the boundary.
  Where classify(const gp_XYZ& x, double margin) const {
    const gp_XY q = uvOf(x);
    const double band = deflection_ + margin;
    bool odd = false;
    for (const Flat& flat : flats_) {
      if (q.Y() < flat.lo.Y() - band || q.Y() > flat.hi.Y() + band || q.X() > flat.hi.X() + band) continue;
      const bool close = q.X() >= flat.lo.X() - band;
      for (std::size_t k = 0; k + 1 < flat.points.size(); ++k) {
        const gp_XY& a = flat.points[k];
        const gp_XY& b = flat.points[k + 1];
        if (close && distanceToSegment(q, a, b) <= band) return Where::Near;
        if ((a.Y() > q.Y()) != (b.Y() > q.Y()) && q.X() < a.X() + (q.Y() - a.Y()) * (b.X() - a.X()) / (b.Y() - a.Y()))
          odd = !odd;
      }
    }
    return odd ? Where::In : Where::Out;
  }

 private:
  struct Flat {
    std::vector<gp_XY> points;
    gp_XY lo{kInfinity, kInfinity}, hi{-kInfinity, -kInfinity};
  };

  gp_XY uvOf(const gp_XYZ& p) const {
    double u, v;
    ElSLib::Parameters(plane_, gp_Pnt(p), u, v);
    return {u, v};
  }

  static double distanceToSegment(const gp_XY& q, const gp_XY& a, const gp_XY& b) {
    const gp_XY ab = b - a, aq = q - a;
    const double length2 = ab.SquareModulus();
    const double t = length2 > 0 ? std::clamp(aq.Dot(ab) / length2, 0.0, 1.0) : 0.0;
    return (aq - ab * t).Modulus();
  }

  gp_Pln plane_;
  double deflection_;
  std::vector<Flat> flats_;
};

struct FaceInfo {
  TopoDS_Face face;
  int solid = 0;
  bool planar = false;
  gp_Pln plane;
  double tolerance = 0;   // the largest of the face's, its edges' and its vertices'
  Box3 box;
  // Built on first use (confirmations and planar classifications are rare).
  std::unique_ptr<BRepTopAdaptor_FClass2d> classifier;
  Handle(ShapeAnalysis_Surface) surface;
  std::unique_ptr<BRepAdaptor_Surface> adaptor;
  std::unique_ptr<PlanarRegion> region;  // planar faces
};

class CrossingFinder {
 public:
  CrossingFinder(const TopoDS_Shape& shape, const CrossingBudgets& budgets) : shape_(shape), budgets_(budgets) {
    Bnd_Box box;
    BRepBndLib::Add(shape, box);
    diagonal_ = box.IsVoid() ? 1.0 : std::sqrt(box.SquareExtent());
    result_.deflection = kRelativeDeflection * diagonal_;
  }

  CrossingSearch run() {
    collectFaces();
    meshCurvedFaces();
    Bvh bvh(primitives_);
    long left = budgets_.boxPairsPerPrimitive * static_cast<long>(primitives_.size()) + budgets_.boxPairsAtLeast;
    result_.pairsStopped = !bvh.forEachOverlappingPair([this, &left](const Primitive& a, const Primitive& b) {
      test(a, b);
      return --left > 0;
    });
    confirmCandidates();
    return std::move(result_);
  }

 private:
  void collectFaces() {
    TopTools_IndexedMapOfShape solids;
    TopExp::MapShapes(shape_, TopAbs_SOLID, solids);
    TopExp::MapShapes(shape_, TopAbs_FACE, faceMap_);
    faces_.resize(faceMap_.Extent());
    for (int s = 1; s <= solids.Extent(); ++s)
      for (TopExp_Explorer ex(solids(s), TopAbs_FACE); ex.More(); ex.Next()) {
        const int index = faceMap_.FindIndex(ex.Current());
        if (index > 0 && faces_[index - 1].solid == 0) faces_[index - 1].solid = s;
      }
    for (int i = 0; i < faceMap_.Extent(); ++i) {
      FaceInfo& f = faces_[i];
      f.face = TopoDS::Face(faceMap_(i + 1));
      f.tolerance = BRep_Tool::Tolerance(f.face);
      for (TopExp_Explorer ex(f.face, TopAbs_EDGE); ex.More(); ex.Next())
        f.tolerance = std::max(f.tolerance, BRep_Tool::Tolerance(TopoDS::Edge(ex.Current())));
      for (TopExp_Explorer ex(f.face, TopAbs_VERTEX); ex.More(); ex.Next())
        f.tolerance = std::max(f.tolerance, BRep_Tool::Tolerance(TopoDS::Vertex(ex.Current())));
      const BRepAdaptor_Surface surface(f.face, false);
      f.planar = surface.GetType() == GeomAbs_Plane;
      if (f.planar) {
        f.plane = surface.Plane();
        Bnd_Box box;
        BRepBndLib::Add(f.face, box, false);
        f.box = toBox3(box);
        f.box.enlarge(f.tolerance);
        primitives_.push_back({f.box, i, -1});
      }
    }
  }

  // The curved faces of a copy (the shape is never modified: BRepMesh stores its triangles
  // in the faces), meshed together so that neighbours share the nodes of their edges.
  // Within a budget of BRepMesh's progress checks (MeshingBudget): the faces it leaves
  // without triangles are reported as not searched. So are the faces whose edges stray
  // from them (curve_on_face.hpp: kMaxEdgeStray), which the mesh back end does not give
  // BRepMesh either: BRepMesh's Delaunay mends such a face's boundary without asking its
  // progress indicator (fuzz_brep: a cylinder whose seam lay 229 mm off it, 1,025 points
  // a side, 33 s in Release).
  void meshCurvedFaces() {
    const TopoDS_Shape copy = BRepBuilderAPI_Copy(shape_, false, false).Shape();
    TopTools_IndexedMapOfShape copyFaces;
    TopExp::MapShapes(copy, TopAbs_FACE, copyFaces);
    std::vector<bool> offItsEdges(faces_.size(), false);
    for (const FaceOffItsEdges& off : curvedFacesOffTheirEdges(shape_, kMaxEdgeStray * diagonal_))
      if (off.face <= static_cast<int>(faces_.size())) offItsEdges[off.face - 1] = true;
    TopoDS_Compound curved;
    BRep_Builder builder;
    builder.MakeCompound(curved);
    bool any = false;
    for (int i = 0; i < static_cast<int>(faces_.size()) && i < copyFaces.Extent(); ++i) {
      if (faces_[i].planar) continue;
      if (offItsEdges[i]) {
        result_.unmeshed.push_back(faces_[i].face);
        continue;
      }
      builder.Add(curved, copyFaces(i + 1));
      any = true;
    }
    if (!any) return;
    const Handle(MeshingBudget) budget =
        new MeshingBudget(budgets_.meshingChecksAtLeast + budgets_.meshingChecksPerFace * static_cast<long>(faces_.size()));
    meshWithin(curved, {result_.deflection, kAngularDeflection}, budget);
    result_.meshingStopped = budget->spent();
    for (int i = 0; i < static_cast<int>(faces_.size()) && i < copyFaces.Extent(); ++i) {
      if (faces_[i].planar || offItsEdges[i]) continue;
      TopLoc_Location location;
      const Handle(Poly_Triangulation) mesh = BRep_Tool::Triangulation(TopoDS::Face(copyFaces(i + 1)), location);
      if (mesh.IsNull() || mesh->NbTriangles() == 0) {
        result_.unmeshed.push_back(faces_[i].face);
        continue;
      }
      addTriangles(i, *mesh, location.Transformation());
    }
  }

  void addTriangles(int face, const Poly_Triangulation& mesh, const gp_Trsf& trsf) {
    const double eps = faces_[face].tolerance;
    for (int t = 1; t <= mesh.NbTriangles(); ++t) {
      int n[3];
      mesh.Triangle(t).Get(n[0], n[1], n[2]);
      Triangle triangle;
      triangle.face = face;
      triangle.hasUV = mesh.HasUVNodes();
      Primitive primitive;
      for (int k = 0; k < 3; ++k) {
        triangle.p[k] = mesh.Node(n[k]).Transformed(trsf).XYZ();
        if (triangle.hasUV) triangle.uv[k] = mesh.UVNode(n[k]).XY();
        primitive.box.add(triangle.p[k]);
      }
      primitive.box.enlarge(eps);
      primitive.face = face;
      primitive.triangle = static_cast<int>(triangles_.size());
      triangles_.push_back(triangle);
      primitives_.push_back(primitive);
    }
  }

  // Beyond this, a point is off a face's surface: its tolerances, and rounding.
  double epsilon(int a, int b) const {
    return std::max(faces_[a].tolerance, faces_[b].tolerance) + 1e-9 * diagonal_;
  }
  // How far a crossing must be from the faces' vertices and boundaries to count: a few
  // times their tolerances.
  double margin(int a, int b) const {
    return std::max(4 * std::max(faces_[a].tolerance, faces_[b].tolerance), 1e-7 * diagonal_);
  }

  void test(const Primitive& p, const Primitive& q) {
    if (p.face == q.face) return;
    if (p.triangle >= 0 && q.triangle >= 0) {
      const Triangle& a = triangles_[p.triangle];
      const Triangle& b = triangles_[q.triangle];
      if (const auto x = trianglesCross(a.p, b.p, epsilon(p.face, q.face))) {
        Candidate c{*x, {}};
        if (a.hasUV) c.uv[0] = interpolateUV(a, *x);
        if (b.hasUV) c.uv[1] = interpolateUV(b, *x);
        addCandidate(p.face, q.face, c);
      }
    } else if (p.triangle >= 0) {
      triangleThroughPlane(triangles_[p.triangle], q.face);
    } else if (q.triangle >= 0) {
      triangleThroughPlane(triangles_[q.triangle], p.face);
    } else {
      planesCross(p.face, q.face);
    }
  }

  // A triangle that crosses a planar face's plane inside the face.
  void triangleThroughPlane(const Triangle& t, int planar) {
    const gp_Pln& plane = faces_[planar].plane;
    const gp_XYZ n = plane.Axis().Direction().XYZ(), o = plane.Location().XYZ();
    std::array<double, 3> d;
    for (int k = 0; k < 3; ++k) d[k] = (t.p[k] - o).Dot(n);
    if (!straddles(d, epsilon(t.face, planar))) return;
    const auto s = sectionOnPlane(t.p, d);
    for (const double u : {0.5, 0.2, 0.8}) {
      const gp_XYZ x = s[0] + (s[1] - s[0]) * u;
      if (region(planar).classify(x, margin(t.face, planar)) != PlanarRegion::Where::In) continue;
      Candidate c{x, {}};
      if (t.hasUV) c.uv[0] = interpolateUV(t, x);
      addCandidate(t.face, planar, c);
      return;
    }
  }

  // Two planar faces cross where the line their planes meet in runs inside both: the spans
  // of the line inside each face overlap by more than their boundaries' band. (An edge of
  // one piercing the other starts such an overlap; so do two faces crossed like an X, whose
  // crossing ends on the edges of both.)
  void planesCross(int a, int b) {
    const gp_Pln& pa = faces_[a].plane;
    const gp_Pln& pb = faces_[b].plane;
    const gp_XYZ na = pa.Axis().Direction().XYZ(), nb = pb.Axis().Direction().XYZ();
    const gp_XYZ along = na.Crossed(nb);
    if (along.Modulus() < kMinSine) return;  // parallel planes only touch
    // The point of the line nearest a's origin: on both planes.
    const gp_XYZ oa = pa.Location().XYZ(), ob = pb.Location().XYZ();
    const double c = na.Dot(nb), det = 1 - c * c;
    const double ra = na.Dot(oa), rb = nb.Dot(ob);
    const gp_XYZ origin = na * ((ra - c * rb) / det) + nb * ((rb - c * ra) / det);
    const gp_Lin line{gp_Pnt(origin), gp_Dir(along)};
    const double m = margin(a, b);
    const auto spansA = region(a).spansAlong(line, m), spansB = region(b).spansAlong(line, m);
    for (const auto& [a0, a1] : spansA)
      for (const auto& [b0, b1] : spansB) {
        const double lo = std::max(a0, b0), hi = std::min(a1, b1);
        if (!(hi - lo > 0)) continue;
        const gp_XYZ x = (line.Location().XYZ() + line.Direction().XYZ() * ((lo + hi) / 2));
        if (region(a).classify(x, m) == PlanarRegion::Where::In && region(b).classify(x, m) == PlanarRegion::Where::In)
          addCandidate(a, b, Candidate{x, {}});
      }
  }

  const PlanarRegion& region(int planar) {
    FaceInfo& f = faces_[planar];
    if (!f.region) f.region = std::make_unique<PlanarRegion>(f.face, f.plane, kBoundaryDeflection * result_.deflection);
    return *f.region;
  }

  void addCandidate(int a, int b, Candidate c) {
    if (a > b) {
      std::swap(a, b);
      std::swap(c.uv[0], c.uv[1]);
    }
    std::vector<Candidate>& list = candidates_[{a, b}];
    if (static_cast<int>(list.size()) < kCandidatesPerPair) list.push_back(c);
  }

  // --- on the exact surfaces -------------------------------------------------------------

  BRepTopAdaptor_FClass2d& classifier(int face) {
    FaceInfo& f = faces_[face];
    if (!f.classifier) {
      const BRepAdaptor_Surface& s = adaptor(face);
      const double tol = std::max({s.UResolution(f.tolerance), s.VResolution(f.tolerance), Precision::PConfusion()});
      f.classifier = std::make_unique<BRepTopAdaptor_FClass2d>(TopoDS::Face(f.face.Oriented(TopAbs_FORWARD)), tol);
    }
    return *f.classifier;
  }

  const BRepAdaptor_Surface& adaptor(int face) {
    FaceInfo& f = faces_[face];
    if (!f.adaptor) f.adaptor = std::make_unique<BRepAdaptor_Surface>(f.face, false);
    return *f.adaptor;
  }

  ShapeAnalysis_Surface& projector(int face) {
    FaceInfo& f = faces_[face];
    if (f.surface.IsNull()) f.surface = new ShapeAnalysis_Surface(BRep_Tool::Surface(f.face));
    return *f.surface;
  }

  struct OnSurface {
    gp_Pnt2d uv;
    gp_Pnt point;
    gp_Dir normal;
  };

  std::optional<OnSurface> project(int face, const gp_Pnt& x, const std::optional<gp_Pnt2d>& hint) {
    ShapeAnalysis_Surface& surface = projector(face);
    const double precision = std::max(faces_[face].tolerance, Precision::Confusion());
    const gp_Pnt2d uv = hint ? surface.NextValueOfUV(*hint, x, precision) : surface.ValueOfUV(x, precision);
    gp_Pnt p;
    gp_Vec du, dv;
    adaptor(face).D1(uv.X(), uv.Y(), p, du, dv);
    const gp_Vec n = du.Crossed(dv);
    if (n.Magnitude() < gp::Resolution()) return std::nullopt;
    return OnSurface{uv, p, gp_Dir(n)};
  }

  // Newton's method for a point on both surfaces near x: step to the point nearest x on the
  // line where the two tangent planes meet. Fails where the surfaces are (nearly) tangent
  // there: touching is not crossing.
  struct Meeting {
    gp_Pnt point;
    gp_Pnt2d uv[2];
    gp_Dir along;  // the direction of the curve where they meet
  };

  std::optional<Meeting> meet(int a, int b, gp_Pnt x, std::optional<gp_Pnt2d> hintA, std::optional<gp_Pnt2d> hintB) {
    const double tol = faces_[a].tolerance + faces_[b].tolerance + 1e-9 * diagonal_;
    for (int iteration = 0; iteration < 16; ++iteration) {
      const auto pa = project(a, x, hintA);
      const auto pb = project(b, x, hintB);
      if (!pa || !pb) return std::nullopt;
      hintA = pa->uv;
      hintB = pb->uv;
      const gp_XYZ na = pa->normal.XYZ(), nb = pb->normal.XYZ();
      const gp_XYZ along = na.Crossed(nb);
      const double sine = along.Modulus();
      if (sine < kMinSine) return std::nullopt;
      if (pa->point.Distance(pb->point) <= tol && pa->point.Distance(x) <= tol)
        return Meeting{gp_Pnt((pa->point.XYZ() + pb->point.XYZ()) / 2), {pa->uv, pb->uv}, gp_Dir(along)};
      // y = x + l1 na + l2 nb on both tangent planes.
      const double c = na.Dot(nb);
      const double r1 = na.Dot(pa->point.XYZ() - x.XYZ()), r2 = nb.Dot(pb->point.XYZ() - x.XYZ());
      const double det = 1 - c * c;
      const double l1 = (r1 - c * r2) / det, l2 = (r2 - c * r1) / det;
      x = gp_Pnt(x.XYZ() + na * l1 + nb * l2);
    }
    return std::nullopt;
  }

  bool nearVertex(int face, const gp_Pnt& p, double margin) const {
    for (TopExp_Explorer ex(faces_[face].face, TopAbs_VERTEX); ex.More(); ex.Next()) {
      const TopoDS_Vertex& v = TopoDS::Vertex(ex.Current());
      if (p.Distance(BRep_Tool::Pnt(v)) <= margin + BRep_Tool::Tolerance(v)) return true;
    }
    return false;
  }

  // A confirmed crossing: the surfaces meet at an angle at a point inside both faces and
  // away from their vertices. A meeting on the boundary of one face (its edge pierces the
  // other) is followed along the curve where the surfaces meet, into both faces.
  std::optional<gp_Pnt> confirm(int a, int b, const Candidate& c) {
    const double m = margin(a, b);
    std::optional<gp_Pnt2d> hintA, hintB;
    if (c.uv[0]) hintA = gp_Pnt2d(*c.uv[0]);
    if (c.uv[1]) hintB = gp_Pnt2d(*c.uv[1]);
    const auto start = meet(a, b, gp_Pnt(c.point), hintA, hintB);
    if (!start) return std::nullopt;
    if (insideBoth(a, b, *start, m)) return start->point;
    for (const double step : {10 * m, result_.deflection / 4})
      for (const double sense : {1.0, -1.0}) {
        const gp_Pnt x(start->point.XYZ() + start->along.XYZ() * (sense * step));
        const auto moved = meet(a, b, x, start->uv[0], start->uv[1]);
        if (moved && insideBoth(a, b, *moved, m)) return moved->point;
      }
    return std::nullopt;
  }

  bool insideBoth(int a, int b, const Meeting& meeting, double m) {
    return classifier(a).Perform(meeting.uv[0], false) == TopAbs_IN &&
           classifier(b).Perform(meeting.uv[1], false) == TopAbs_IN && !nearVertex(a, meeting.point, m) &&
           !nearVertex(b, meeting.point, m);
  }

  // Within one solid first (the defects), then between solids; one crossing per pair of
  // solids is enough to know their volumes overlap.
  void confirmCandidates() {
    std::vector<std::pair<int, int>> pairs;
    for (const auto& [key, list] : candidates_) pairs.push_back(key);
    std::stable_partition(pairs.begin(), pairs.end(),
                          [this](const auto& p) { return faces_[p.first].solid == faces_[p.second].solid; });
    if (static_cast<int>(pairs.size()) > kMaxPairs) {
      pairs.resize(kMaxPairs);
      result_.truncated = true;
    }
    std::map<std::pair<int, int>, bool> solidsCross;
    int confirmations = 0;
    for (const auto& [a, b] : pairs) {
      const int sa = faces_[a].solid, sb = faces_[b].solid;
      if (sa != sb && solidsCross[{std::min(sa, sb), std::max(sa, sb)}]) continue;
      for (const Candidate& c : candidates_[{a, b}]) {
        if (++confirmations > kMaxConfirmations) {
          result_.truncated = true;
          return;
        }
        std::optional<gp_Pnt> where;
        try {
          where = confirm(a, b, c);
        } catch (const Standard_Failure&) {
          where.reset();  // a projection that failed confirms nothing
        }
        if (!where) continue;
        result_.crossings.push_back({faces_[a].face, faces_[b].face, sa, sb, *where});
        if (sa != sb) solidsCross[{std::min(sa, sb), std::max(sa, sb)}] = true;
        break;
      }
    }
  }

  const TopoDS_Shape& shape_;
  const CrossingBudgets budgets_;
  double diagonal_ = 1;
  TopTools_IndexedMapOfShape faceMap_;
  std::vector<FaceInfo> faces_;
  std::vector<Triangle> triangles_;
  std::vector<Primitive> primitives_;
  std::map<std::pair<int, int>, std::vector<Candidate>> candidates_;
  CrossingSearch result_;
};

}  // namespace

CrossingSearch findFaceCrossings(const TopoDS_Shape& shape, const CrossingBudgets& budgets) {
  return CrossingFinder(shape, budgets).run();
}

}  // namespace hg::geometry
