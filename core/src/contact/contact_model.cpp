#include "hapticgrasp/contact/contact_model.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRep_Tool.hxx>
#include <GCPnts_AbscissaPoint.hxx>
#include <Geom2d_Curve.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "hapticgrasp/geometry/tessellation.hpp"

namespace hg::contact {
namespace {

using geometry::PartModel;

// A sharp convex edge: its index, length (m) and its two faces.
struct SharpEdge {
  int index = 0;
  double length_m = 0;
  TopoDS_Face faces[2];
  int faceIndex[2] = {0, 0};
};

// The outward unit normal of `face` where `edge` runs through it at the edge's parameter
// t (its pcurve shares the edge's parameter in a valid B-rep); zero where degenerate.
Vec3 faceNormalAlongEdge(const TopoDS_Face& face, const TopoDS_Edge& edge, double t) {
  double first = 0, last = 0;
  const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
  if (pcurve.IsNull()) return Vec3::Zero();
  const gp_Pnt2d uv = pcurve->Value(std::clamp(t, std::min(first, last), std::max(first, last)));
  const BRepAdaptor_Surface surface(face);
  gp_Pnt p;
  gp_Vec du, dv;
  surface.D1(uv.X(), uv.Y(), p, du, dv);
  gp_Vec n = du.Crossed(dv);
  if (n.Magnitude() < 1e-15) return Vec3::Zero();
  n.Normalize();
  if (face.Orientation() == TopAbs_REVERSED) n.Reverse();
  return {n.X(), n.Y(), n.Z()};
}

// A point of `edge` at parameter t, in metres, with the bisector of its faces' normals.
struct EdgeSample {
  Vec3 position, n0, n1;
};
EdgeSample sampleEdge(const PartModel& part, const SharpEdge& e, const BRepAdaptor_Curve& curve, double t) {
  const TopoDS_Edge& edge = TopoDS::Edge(part.edges().FindKey(e.index));
  const gp_Pnt p = curve.Value(t);
  return {Vec3(p.X(), p.Y(), p.Z()) * part.metresPerUnit(), faceNormalAlongEdge(e.faces[0], edge, t),
          faceNormalAlongEdge(e.faces[1], edge, t)};
}

// The part's edges between two faces whose normals differ by more than the sharp angle
// and that bulge outwards.
std::vector<SharpEdge> sharpConvexEdges(const PartModel& part, const geometry::PenetrationModel& penetration,
                                        double sharpAngle_rad) {
  TopTools_IndexedDataMapOfShapeListOfShape facesOfEdge;
  TopExp::MapShapesAndAncestors(part.shape(), TopAbs_EDGE, TopAbs_FACE, facesOfEdge);
  const double probe_m = 1e-4 * part.characteristicLength();
  std::vector<SharpEdge> sharp;
  for (int i = 1; i <= part.edges().Extent(); ++i) {
    const TopoDS_Edge& edge = TopoDS::Edge(part.edges().FindKey(i));
    if (BRep_Tool::Degenerated(edge) || !facesOfEdge.Contains(edge)) continue;
    SharpEdge e;
    e.index = i;
    int found = 0;
    for (const TopoDS_Shape& f : facesOfEdge.FindFromKey(edge)) {
      const int index = part.faces().FindIndex(f);
      if (found == 1 && index == e.faceIndex[0]) continue;  // a seam: one face on both sides
      e.faces[found] = TopoDS::Face(f);
      e.faceIndex[found] = index;
      if (++found == 2) break;
    }
    if (found < 2) continue;
    const BRepAdaptor_Curve curve(edge);
    e.length_m = GCPnts_AbscissaPoint::Length(curve) * part.metresPerUnit();
    if (!(e.length_m > 0)) continue;
    const EdgeSample mid = sampleEdge(part, e, curve, 0.5 * (curve.FirstParameter() + curve.LastParameter()));
    if (mid.n0.isZero() || mid.n1.isZero() || mid.n0.dot(mid.n1) > std::cos(sharpAngle_rad)) continue;
    // A point a little way out along the bisector of the normals is outside either way; its
    // nearest surface is the edge itself (distance = probe) when the edge is convex, but
    // the faces (probe cos(theta/2), theta the angle between the normals) when concave.
    geometry::QueryState state;
    const Vec3 bisector = (mid.n0 + mid.n1).normalized();
    const geometry::Penetration probe = penetration.query(mid.position + probe_m * bisector, state);
    const double cosHalf = 0.5 * (mid.n0 + mid.n1).norm();
    if (probe.inside || probe.distance() < probe_m * 0.5 * (1 + cosHalf)) continue;
    sharp.push_back(e);
  }
  return sharp;
}

// h such that faces at area / h^2 and edges at density * length / h points fill `budget`
// (A x^2 + d L x = N in x = 1/h), widened until the minimum counts fit too.
double spacingFor(double area, double edgeLength, double density, int budget, int faces, int edges,
                  const std::vector<double>& faceArea, const std::vector<SharpEdge>& sharp) {
  const double x =
      (-density * edgeLength + std::sqrt(density * density * edgeLength * edgeLength + 4 * area * budget)) / (2 * area);
  double h = 1 / x;
  for (int round = 0; round < 200; ++round) {
    long total = 0;
    for (int f = 1; f <= faces; ++f) total += std::max(1L, std::lround(faceArea[f] / (h * h)));
    for (const SharpEdge& e : sharp) total += std::max(2L, std::lround(density * e.length_m / h) + 1);
    if (total <= budget) break;
    h *= 1.05;
  }
  (void)edges;
  return h;
}

}  // namespace

ContactModelPtr ContactModel::build(geometry::PartModelPtr part, geometry::PenetrationModelPtr penetration,
                                    const ContactModelOptions& options) {
  if (!part || !penetration) throw std::invalid_argument("contact model: missing part or penetration back end");
  if (!penetration->realTimeSafe()) throw std::invalid_argument("contact model: the back end is not real-time safe");
  if (options.maxPoints < 8) throw std::invalid_argument("contact model: a budget of at least 8 points");
  auto model = std::shared_ptr<ContactModel>(new ContactModel());
  model->part_ = part;
  model->penetration_ = penetration;
  model->centre_ = part->bounds().centre();

  const std::vector<SharpEdge> sharp = sharpConvexEdges(*part, *penetration, options.sharpAngle_rad);
  model->sharpEdgeCount_ = static_cast<int>(sharp.size());
  // Faces' areas from a coarse mesh: it only places the points, which are then projected
  // onto the exact surface. Coarse on purpose: at 0.2 % of the part's size (0.3 rad) the mesher took
  // 45 of the 48 s a 1,030-face part's shell cost (measured, `bench contact --part
  // resources/parts/plate.brep`); at 5 % and 1 rad the areas that weight the faces are still close.
  const geometry::Tessellation mesh = geometry::tessellate(*part, 5e-2 * part->characteristicLength(), 1.0);
  const int faces = part->faces().Extent();
  std::vector<double> faceArea(faces + 1, 0.0), triangleArea(mesh.triangles.size());
  double area = 0, edgeLength = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    triangleArea[t] =
        0.5 *
        (mesh.vertices[tri[1]] - mesh.vertices[tri[0]]).cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]).norm();
    faceArea[mesh.triangleFace[t]] += triangleArea[t];
    area += triangleArea[t];
  }
  for (const SharpEdge& e : sharp) edgeLength += e.length_m;
  const double h = spacingFor(area, edgeLength, options.edgeDensity, options.maxPoints, faces, 0, faceArea, sharp);
  model->spacing_m_ = h;

  // Edges: uniform in arc length, ends included (the part's corners).
  for (const SharpEdge& e : sharp) {
    const BRepAdaptor_Curve curve(TopoDS::Edge(part->edges().FindKey(e.index)));
    const int n = static_cast<int>(std::max(2L, std::lround(options.edgeDensity * e.length_m / h) + 1));
    const double total = GCPnts_AbscissaPoint::Length(curve);
    for (int k = 0; k < n; ++k) {
      const double s = total * k / (n - 1);
      const double t = k == 0       ? curve.FirstParameter()
                       : k == n - 1 ? curve.LastParameter()
                                    : GCPnts_AbscissaPoint(curve, s, curve.FirstParameter()).Parameter();
      const EdgeSample sample = sampleEdge(*part, e, curve, t);
      const Vec3 bisector = sample.n0 + sample.n1;
      if (bisector.norm() < 1e-9) continue;
      model->points_.push_back({sample.position, bisector.normalized(), 0, e.faceIndex[0], e.index});
    }
  }
  model->edgePoints_ = model->points_.size();

  // Faces: area-weighted over their triangles, one seeded stream a face (deterministic),
  // each point projected onto the exact surface, which gives its outward normal.
  std::vector<std::vector<int>> trianglesOf(faces + 1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    trianglesOf[mesh.triangleFace[t]].push_back(static_cast<int>(t));
  for (int f = 1; f <= faces; ++f) {
    if (trianglesOf[f].empty()) continue;
    std::vector<double> cumulative;
    double sum = 0;
    for (int t : trianglesOf[f]) cumulative.push_back(sum += triangleArea[t]);
    const long n = std::max(1L, std::lround(faceArea[f] / (h * h)));
    std::mt19937 rng(static_cast<unsigned>(f));
    std::uniform_real_distribution<double> unit(0, 1);
    for (long k = 0; k < n; ++k) {
      const auto it = std::lower_bound(cumulative.begin(), cumulative.end(), unit(rng) * sum);
      const auto& tri =
          mesh.triangles[trianglesOf[f][std::min<std::size_t>(it - cumulative.begin(), cumulative.size() - 1)]];
      double a = unit(rng), b = unit(rng);
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const Vec3 p0 = mesh.vertices[tri[0]];
      const Vec3 x = p0 + a * (mesh.vertices[tri[1]] - p0) + b * (mesh.vertices[tri[2]] - p0);
      geometry::QueryState state;
      const geometry::Penetration q = penetration->query(x, state);
      if (q.normal.isZero() || !q.foot.allFinite()) continue;
      const int face = q.feature == geometry::Feature::Face ? q.featureIndex : f;
      model->points_.push_back({q.foot, q.normal.normalized(), 0, face, 0});
    }
  }
  // Hundreds of small faces and short edges: their minimum counts alone exceed the budget.
  // Thinned evenly (edges and faces alike, order kept) so that the budget holds.
  if (model->points_.size() > static_cast<std::size_t>(options.maxPoints)) {
    std::vector<ShellPoint> kept;
    kept.reserve(options.maxPoints);
    std::size_t edgesKept = 0;
    const double stride = static_cast<double>(model->points_.size()) / options.maxPoints;
    for (int i = 0; i < options.maxPoints; ++i) {
      const auto k = static_cast<std::size_t>(i * stride);
      kept.push_back(model->points_[k]);
      if (k < model->edgePoints_) ++edgesKept;
    }
    model->points_ = std::move(kept);
    model->edgePoints_ = edgesKept;
  }
  for (ShellPoint& p : model->points_) {
    p.reach = (p.position - model->centre_).norm();
    model->radius_ = std::max(model->radius_, p.reach);
  }
  return model;
}

}  // namespace hg::contact
