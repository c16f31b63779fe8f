// The exact back end: per-feature projection on the B-rep's own surfaces and curves.
// Candidates are the faces (foot inside the trimmed face), the edges (foot inside the
// edge) and the vertices; a BVH over their boxes visits the nearest first and prunes the
// rest. The sign comes from the feature: the face normal, the sum of an edge's two face
// normals, or a vertex's angle-weighted pseudo-normal — no solid classifier per query.
// Coherent motion is warm-started from the last tick's feature and parameters.
#include <BRepBndLib.hxx>
#include <Bnd_Box.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>

#include <cmath>
#include <string>

#include "edge_model.hpp"
#include "face_model.hpp"
#include "feature_bvh.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "vertex_model.hpp"

namespace hg::geometry {
namespace {

using exact::EdgeFoot;
using exact::EdgeModel;
using exact::FaceFoot;
using exact::FaceModel;
using exact::FeatureRef;
using exact::VertexModel;

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

Aabb boxOf(const TopoDS_Shape& shape, double margin) {
  Bnd_Box box;
  BRepBndLib::AddOptimal(shape, box, false, true);
  double x0, y0, z0, x1, y1, z1;
  box.Get(x0, y0, z0, x1, y1, z1);
  return Aabb{Vec3(x0, y0, z0), Vec3(x1, y1, z1)}.inflated(margin);
}

// Faces are preferred to edges, edges to vertices, where two are equally close.
int rank(Feature f) { return f == Feature::Face ? 0 : f == Feature::Edge ? 1 : 2; }

// The features a query examined, with where their searches ended: next tick's warm starts.
struct Examined {
  static constexpr int kCapacity = 16;
  WarmStart entries[kCapacity];
  int count = 0;
  void add(Feature kind, int index, double u, double v) {
    if (count < kCapacity) entries[count++] = {kind, index + 1, u, v};
  }
};

// The best candidate so far, in model units.
struct Candidate {
  Feature kind = Feature::None;
  int index = -1;  // 0-based
  double u = 0, v = 0;
  gp_Pnt foot;
  double distance = INFINITY;
};

class ExactPenetration final : public PenetrationModel {
 public:
  explicit ExactPenetration(PartModelPtr part);

  std::string_view name() const noexcept override { return "exact"; }
  std::string setting() const override { return "B-rep, " + std::to_string(faces_.size()) + " faces"; }
  std::size_t memoryBytes() const noexcept override;
  Penetration query(const Vec3& x, QueryState& state) const noexcept override;

 protected:
  bool queryFeature(const Vec3& x, Feature feature, int index, double& u, double& v,
                    Penetration& out) const noexcept override;

 private:
  void evaluate(FeatureRef f, const gp_Pnt& x, const WarmStart* warm, Examined& examined, Candidate& best) const noexcept;
  bool better(Feature kind, double d, const Candidate& best) const noexcept {
    return d < best.distance - tie_ || (d <= best.distance + tie_ && rank(kind) < rank(best.kind));
  }
  gp_Vec outwardAt(const Candidate& c) const noexcept;
  Penetration answer(const gp_Pnt& x, const Candidate& c) const noexcept;

  PartModelPtr part_;
  double s_;     // metres per model unit
  double tie_;   // model units: distances closer than this are equal
  std::vector<FaceModel> faces_;
  std::vector<EdgeModel> edges_;
  std::vector<VertexModel> vertices_;
  exact::FeatureBvh bvh_;
};

ExactPenetration::ExactPenetration(PartModelPtr part) : part_(std::move(part)), s_(part_->metresPerUnit()) {
  const double L = part_->characteristicLength() / s_;
  tie_ = 1e-12 * L;
  const double margin = 1e-9 * L;
  const TopTools_IndexedMapOfShape& faces = part_->faces();
  faces_.reserve(faces.Extent());
  for (int i = 1; i <= faces.Extent(); ++i) {
    faces_.emplace_back(TopoDS::Face(faces(i)), L);
    bvh_.add({Feature::Face, i - 1}, boxOf(faces(i), margin));
  }
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndUniqueAncestors(part_->shape(), TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  const TopTools_IndexedMapOfShape& edges = part_->edges();
  edges_.reserve(edges.Extent());
  for (int i = 1; i <= edges.Extent(); ++i) {
    std::vector<std::pair<TopoDS_Face, int>> adjacent;
    if (const TopTools_ListOfShape* list = edgeFaces.Seek(edges(i)))
      for (const TopoDS_Shape& f : *list) {
        const int fi = faces.FindIndex(f);
        if (fi > 0) adjacent.emplace_back(TopoDS::Face(faces(fi)), fi - 1);
      }
    edges_.emplace_back(TopoDS::Edge(edges(i)), adjacent);
    if (edges_.back().usable()) bvh_.add({Feature::Edge, i - 1}, boxOf(edges(i), margin));
  }
  vertices_ = exact::buildVertexModels(part_->vertices(), faces, faces_);
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vec3 p = toVec(vertices_[i].point.XYZ());
    bvh_.add({Feature::Vertex, static_cast<int>(i)}, Aabb{p, p}.inflated(margin));
  }
  bvh_.build();
}

void ExactPenetration::evaluate(FeatureRef f, const gp_Pnt& x, const WarmStart* warm, Examined& examined,
                                Candidate& best) const noexcept {
  double u = warm ? warm->u : 0, v = warm ? warm->v : 0;
  switch (f.kind) {
    case Feature::Face: {
      FaceFoot foot;
      const bool found = faces_[f.index].project(x, warm != nullptr, u, v, best.distance + tie_, foot);
      examined.add(Feature::Face, f.index, u, v);
      if (found && better(Feature::Face, foot.distance, best))
        best = {Feature::Face, f.index, foot.u, foot.v, foot.point, foot.distance};
      break;
    }
    case Feature::Edge: {
      EdgeFoot foot;
      const bool found = edges_[f.index].project(x, warm != nullptr, u, best.distance + tie_, foot);
      examined.add(Feature::Edge, f.index, u, 0);
      if (found && better(Feature::Edge, foot.distance, best))
        best = {Feature::Edge, f.index, foot.t, 0, foot.point, foot.distance};
      break;
    }
    case Feature::Vertex: {
      const double d = vertices_[f.index].point.Distance(x);
      if (better(Feature::Vertex, d, best)) best = {Feature::Vertex, f.index, 0, 0, vertices_[f.index].point, d};
      break;
    }
    default: break;
  }
}

// The outward direction at the candidate's foot that decides the sign.
gp_Vec ExactPenetration::outwardAt(const Candidate& c) const noexcept {
  switch (c.kind) {
    case Feature::Face: return faces_[c.index].normalAt(c.u, c.v);
    case Feature::Edge: return edges_[c.index].pseudoNormal(c.u, faces_);
    default: return vertices_[c.index].pseudoNormal;
  }
}

Penetration ExactPenetration::answer(const gp_Pnt& x, const Candidate& c) const noexcept {
  Penetration p;
  const gp_Vec outward = outwardAt(c);
  const gp_Vec offset(c.foot, x);
  p.inside = c.distance > 0 && offset.Dot(outward) < 0;
  p.depth = (p.inside ? c.distance : -c.distance) * s_;
  p.foot = toVec(c.foot.XYZ()) * s_;
  p.vector = toVec(offset.XYZ()) * s_;
  if (c.kind == Feature::Face || c.distance <= tie_) {
    p.normal = toVec(outward.XYZ()).normalized();
  } else {  // at an edge or vertex the outward normal is the direction away from the foot
    p.normal = toVec(offset.XYZ()) / c.distance;
    if (p.inside) p.normal = -p.normal;
  }
  p.feature = c.kind;
  p.featureIndex = c.index + 1;
  return p;
}

// The warm start a state holds for feature f, if any.
const WarmStart* warmStartFor(const QueryState& state, FeatureRef f) {
  if (state.feature == f.kind && state.index == f.index + 1) return nullptr;  // handled first
  for (const WarmStart& w : state.neighbours)
    if (w.feature == f.kind && w.index == f.index + 1) return &w;
  return nullptr;
}

Penetration ExactPenetration::query(const Vec3& xm, QueryState& state) const noexcept {
  if (!xm.allFinite()) return {};
  try {
    const Vec3 xu = xm / s_;
    const gp_Pnt x(xu.x(), xu.y(), xu.z());
    Candidate best;
    Examined examined;
    // Last tick's closest feature first: its distance prunes most of the BVH.
    const FeatureRef last{state.feature, state.index - 1};
    const WarmStart lastStart{state.feature, state.index, state.u, state.v};
    if (state.feature != Feature::None) evaluate(last, x, &lastStart, examined, best);
    bvh_.nearest(
        xu,
        [&](FeatureRef f) {
          if (f.kind != last.kind || f.index != last.index) evaluate(f, x, warmStartFor(state, f), examined, best);
        },
        [&] { return (best.distance + tie_) * (best.distance + tie_); });
    if (best.kind == Feature::None) return {};
    state.feature = best.kind;
    state.index = best.index + 1;
    state.u = best.u;
    state.v = best.v;
    int n = 0;
    for (int i = 0; i < examined.count && n < QueryState::kNeighbours; ++i)
      if (!(examined.entries[i].feature == best.kind && examined.entries[i].index == best.index + 1))
        state.neighbours[n++] = examined.entries[i];
    for (; n < QueryState::kNeighbours; ++n) state.neighbours[n] = {};
    return answer(x, best);
  } catch (const Standard_Failure&) {
    return {};  // a surface that cannot be evaluated here: no contact rather than a crash
  }
}

bool ExactPenetration::queryFeature(const Vec3& xm, Feature feature, int index, double& u, double& v,
                                    Penetration& out) const noexcept {
  if (!xm.allFinite() || index < 1) return false;
  try {
    const Vec3 xu = xm / s_;
    const gp_Pnt x(xu.x(), xu.y(), xu.z());
    Candidate held;
    Examined examined;
    const WarmStart start{feature, index, u, v};
    evaluate({feature, index - 1}, x, &start, examined, held);
    if (held.kind == Feature::None) return false;
    u = held.u;
    v = held.v;
    out = answer(x, held);
    // The caller knows x is inside; the held feature's foot is deeper than the closest.
    out.inside = true;
    out.depth = held.distance * s_;
    if (held.kind != Feature::Face && held.distance > tie_) out.normal = -toVec(gp_Vec(held.foot, x).XYZ()) / held.distance;
    return true;
  } catch (const Standard_Failure&) {
    return false;
  }
}

std::size_t ExactPenetration::memoryBytes() const noexcept {
  std::size_t bytes = sizeof(*this) + bvh_.memoryBytes() + vertices_.capacity() * sizeof(VertexModel);
  for (const FaceModel& f : faces_) bytes += f.memoryBytes();
  for (const EdgeModel& e : edges_) bytes += e.memoryBytes();
  return bytes;
}

}  // namespace

PenetrationModelPtr makeExactPenetration(PartModelPtr part) {
  return std::make_shared<ExactPenetration>(std::move(part));
}

}  // namespace hg::geometry
