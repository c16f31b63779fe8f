// The exact back end: per-feature projection on the B-rep's own surfaces and curves.
// Candidates are the faces (foot inside the trimmed face), the edges (foot inside the
// edge) and the vertices; freeform faces and edges enter as their nearly flat patches and
// pieces. A BVH over their bounds visits the nearest first and prunes the rest. The sign
// comes from the feature: the face normal, the sum of an edge's two face normals, or a
// vertex's angle-weighted pseudo-normal — no solid classifier per query. Coherent motion is
// warm-started from the last tick's feature and parameters.
//
// Certainty: elementary faces, lines and circles list every local minimum in closed form.
// A freeform patch or piece searched by Newton is certain where x is clear of its focal
// points; where it is not, the patch is searched exhaustively once the traversal has found
// its best (the fallback), and the answer counts it.
//
// A part made of several solids (a bolt in its nut) is inside where it is inside any of
// them: where the closest feature's own solid says outside, each other solid whose box
// holds x is asked on its own.
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <Bnd_Box.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <memory>
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
using exact::EdgeSearch;
using exact::FaceFoot;
using exact::FaceModel;
using exact::FaceSearch;
using exact::FeatureBvh;
using exact::FeatureRef;
using exact::LeafBound;
using exact::VertexModel;

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

Aabb toAabb(const Bnd_Box& box, double margin) {
  double x0, y0, z0, x1, y1, z1;
  box.Get(x0, y0, z0, x1, y1, z1);
  return Aabb{Vec3(x0, y0, z0), Vec3(x1, y1, z1)}.inflated(margin);
}

// An edge's box from its curve, tight. A face's from its surface's bounds over its
// parameter range, never from a triangulation (which can miss part of the face): looser
// than BRepBndLib::AddOptimal, which optimises every torus by particle swarm (0.5 s of the
// 0.66 s that a 517-face NIST part took to build). But those bounds assume a ring torus:
// on an apple or lemon torus (minor radius above the major) they miss the part near the
// axis, so that one is optimised.
Aabb edgeBox(const TopoDS_Shape& edge, double margin) {
  Bnd_Box box;
  BRepBndLib::AddOptimal(edge, box, false, true);
  return toAabb(box, margin);
}
Aabb faceBox(const TopoDS_Shape& face, double margin) {
  Bnd_Box box;
  const BRepAdaptor_Surface surface(TopoDS::Face(face), false);
  if (surface.GetType() == GeomAbs_Torus && surface.Torus().MinorRadius() >= surface.Torus().MajorRadius())
    BRepBndLib::AddOptimal(face, box, false, true);
  else
    BRepBndLib::Add(face, box, false);
  return toAabb(box, margin);
}

// Faces are preferred to edges, edges to vertices, where two are equally close.
int rank(Feature f) { return f == Feature::Face ? 0 : f == Feature::Edge ? 1 : 2; }

bool same(const WarmStart& w, const FeatureRef& f) {
  return w.feature == f.kind && w.index == f.index + 1 && w.piece == f.piece;
}

// The features a query examined, with where their searches ended: next tick's warm starts.
struct Examined {
  static constexpr int kCapacity = 16;
  WarmStart entries[kCapacity];
  int count = 0;
  void add(const FeatureRef& f, double u, double v) {
    if (count < kCapacity) entries[count++] = {f.kind, f.index + 1, f.piece, u, v};
  }
};

// The best candidate so far, in model units; on a freeform face also its outward normal and
// the surface's last evaluation.
struct Candidate {
  FeatureRef feature;
  double u = 0, v = 0;
  gp_Pnt foot;
  double distance = INFINITY;
  bool hasJet = false;
  gp_Vec normal;
  exact::SurfaceJet jet;
};

Candidate candidate(const FeatureRef& f, double u, double v, const gp_Pnt& foot, double distance) {
  Candidate c;
  c.feature = f;
  c.u = u;
  c.v = v;
  c.foot = foot;
  c.distance = distance;
  return c;
}

Candidate faceCandidate(const FeatureRef& f, const FaceFoot& foot) {
  Candidate c = candidate(f, foot.u, foot.v, foot.point, foot.distance);
  c.hasJet = foot.hasJet;
  c.normal = foot.normal;
  c.jet = foot.jet;
  return c;
}

void store(const exact::SurfaceJet& jet, const FeatureRef& f, SurfaceJetState& out) {
  out.face = f.index + 1;
  out.piece = f.piece;
  out.u = jet.u;
  out.v = jet.v;
  const gp_XYZ* parts[] = {&jet.p.XYZ(), &jet.du.XYZ(), &jet.dv.XYZ(), &jet.duu.XYZ(), &jet.dvv.XYZ(), &jet.duv.XYZ()};
  for (int k = 0; k < 6; ++k)
    for (int c = 0; c < 3; ++c) out.values[3 * k + c] = parts[k]->Coord(c + 1);
}

exact::SurfaceJet load(const SurfaceJetState& in) {
  exact::SurfaceJet jet;
  jet.u = in.u;
  jet.v = in.v;
  auto at = [&in](int k) { return gp_XYZ(in.values[3 * k], in.values[3 * k + 1], in.values[3 * k + 2]); };
  jet.p = gp_Pnt(at(0));
  jet.du = gp_Vec(at(1));
  jet.dv = gp_Vec(at(2));
  jet.duu = gp_Vec(at(3));
  jet.dvv = gp_Vec(at(4));
  jet.duv = gp_Vec(at(5));
  return jet;
}

// One search: the query point, the best so far, and its accounting.
struct Search {
  gp_Pnt x;
  Candidate best;
  Examined examined;
  const exact::SurfaceJet* jet = nullptr;  // last tick's, for the feature it names
  FeatureRef jetFeature;
  // Patches and pieces whose Newton search was not certain when it ran, to settle once the
  // best is known; when there were more than it holds, the whole tree is gone over again.
  struct Unsettled {
    static constexpr int kCapacity = 8;
    FeatureRef entries[kCapacity];
    int count = 0;
    bool overflowed = false;
    bool any() const { return count > 0 || overflowed; }
  } unsettled;
  int fallbacks = 0;
  bool certain = true;
  // Surface or curve evaluations the exhaustive searches of one query may spend: what a
  // servo tick can afford (0.1-0.5 ms). A search left without any is not certain.
  int budget = kFallbackBudget;
  static constexpr int kFallbackBudget = 1000;
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
  void addFeatures(FeatureBvh& bvh, const TopoDS_Shape& solid, double margin) const;
  void evaluate(const FeatureRef& f, const WarmStart* warm, Search& s) const noexcept;
  void settle(const FeatureBvh& bvh, Search& s) const noexcept;
  void exhaust(const FeatureRef& f, Search& s) const noexcept;
  void nearest(const FeatureBvh& bvh, const QueryState& state, Search& s) const noexcept;
  bool better(Feature kind, double d, const Candidate& best) const noexcept {
    return d < best.distance - tie_ || (d <= best.distance + tie_ && rank(kind) < rank(best.feature.kind));
  }
  bool insideOf(const Candidate& c, const gp_Pnt& x) const noexcept;
  gp_Vec outwardAt(const Candidate& c) const noexcept;
  Penetration answer(const gp_Pnt& x, const Candidate& c) const noexcept;
  double lowerBound2(const FeatureRef& f, const gp_Pnt& x) const noexcept {
    const exact::LeafBound& b =
        f.kind == Feature::Face ? faces_[f.index].patches()[f.piece].bound : edges_[f.index].pieces()[f.piece].bound;
    return b.squaredDistance(Vec3(x.X(), x.Y(), x.Z()));
  }
  bool certainFor(const FeatureRef& f, const gp_Pnt& x, double best) const noexcept {
    return f.kind == Feature::Face ? faces_[f.index].certainFor(f.piece, Vec3(x.X(), x.Y(), x.Z()), best)
                                   : edges_[f.index].certainFor(f.piece, best);
  }

  PartModelPtr part_;
  double s_;     // metres per model unit
  double tie_;   // model units: distances closer than this are equal
  std::vector<FaceModel> faces_;
  std::vector<EdgeModel> edges_;
  std::vector<VertexModel> vertices_;
  TopTools_IndexedMapOfShape faceMap_, edgeMap_, vertexMap_;
  FeatureBvh bvh_;  // every feature
  // A part of several solids: each solid's own features, and its box.
  std::vector<FeatureBvh> solidBvhs_;
  std::vector<Aabb> solidBoxes_;
  std::vector<int> faceSolid_;  // the solid each face bounds
  std::vector<Aabb> faceBoxes_, edgeBoxes_;
};

ExactPenetration::ExactPenetration(PartModelPtr part)
    : part_(std::move(part)), s_(part_->metresPerUnit()),
      faceMap_(part_->faces()), edgeMap_(part_->edges()), vertexMap_(part_->vertices()) {
  const double L = part_->characteristicLength() / s_;
  tie_ = 1e-12 * L;
  const double margin = 1e-9 * L;
  faces_.reserve(faceMap_.Extent());
  for (int i = 1; i <= faceMap_.Extent(); ++i) faces_.emplace_back(TopoDS::Face(faceMap_(i)), L);
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndUniqueAncestors(part_->shape(), TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  edges_.reserve(edgeMap_.Extent());
  for (int i = 1; i <= edgeMap_.Extent(); ++i) {
    std::vector<std::pair<TopoDS_Face, int>> adjacent;
    if (const TopTools_ListOfShape* list = edgeFaces.Seek(edgeMap_(i)))
      for (const TopoDS_Shape& f : *list) {
        const int fi = faceMap_.FindIndex(f);
        if (fi > 0) adjacent.emplace_back(TopoDS::Face(faceMap_(fi)), fi - 1);
      }
    edges_.emplace_back(TopoDS::Edge(edgeMap_(i)), adjacent, L);
  }
  vertices_ = exact::buildVertexModels(vertexMap_, faceMap_, faces_);
  // Boxes of the faces and edges answered whole, and of every face (for the solids').
  for (int i = 1; i <= faceMap_.Extent(); ++i) faceBoxes_.push_back(faceBox(faceMap_(i), margin));
  for (int i = 1; i <= edgeMap_.Extent(); ++i)
    edgeBoxes_.push_back(edges_[i - 1].usable() && edges_[i - 1].pieces().empty() ? edgeBox(edgeMap_(i), margin) : Aabb{});

  addFeatures(bvh_, part_->shape(), margin);
  bvh_.build();
  faceSolid_.assign(faces_.size(), 0);
  TopTools_IndexedMapOfShape solids;
  TopExp::MapShapes(part_->shape(), TopAbs_SOLID, solids);
  if (solids.Extent() > 1) {
    solidBvhs_.resize(solids.Extent());
    for (int k = 1; k <= solids.Extent(); ++k) {
      addFeatures(solidBvhs_[k - 1], solids(k), margin);
      solidBvhs_[k - 1].build();
      Aabb box;
      for (TopExp_Explorer ex(solids(k), TopAbs_FACE); ex.More(); ex.Next())
        if (const int fi = faceMap_.FindIndex(ex.Current()); fi > 0) {
          box.extend(faceBoxes_[fi - 1].min);
          box.extend(faceBoxes_[fi - 1].max);
        }
      solidBoxes_.push_back(box);
      for (TopExp_Explorer ex(solids(k), TopAbs_FACE); ex.More(); ex.Next())
        if (const int fi = faceMap_.FindIndex(ex.Current()); fi > 0) faceSolid_[fi - 1] = k - 1;
    }
  }
}

// The leaves of `shape`'s features: each face (or its patches), each edge that can be a
// closest feature (or its pieces), each vertex.
void ExactPenetration::addFeatures(FeatureBvh& bvh, const TopoDS_Shape& shape, double margin) const {
  TopTools_IndexedMapOfShape faces, edges, vertices;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  TopExp::MapShapes(shape, TopAbs_EDGE, edges);
  TopExp::MapShapes(shape, TopAbs_VERTEX, vertices);
  for (int k = 1; k <= faces.Extent(); ++k) {
    const int i = faceMap_.FindIndex(faces(k)) - 1;
    if (i < 0) continue;
    const FaceModel& face = faces_[i];
    if (!face.freeform()) bvh.add({Feature::Face, i, -1}, faceBoxes_[i]);
    for (std::size_t p = 0; p < face.patches().size(); ++p)
      bvh.add({Feature::Face, i, static_cast<int>(p)}, face.patches()[p].bound);
  }
  for (int k = 1; k <= edges.Extent(); ++k) {
    const int i = edgeMap_.FindIndex(edges(k)) - 1;
    if (i < 0 || !edges_[i].usable()) continue;
    const EdgeModel& edge = edges_[i];
    if (edge.pieces().empty()) bvh.add({Feature::Edge, i, -1}, edgeBoxes_[i]);
    for (std::size_t p = 0; p < edge.pieces().size(); ++p)
      bvh.add({Feature::Edge, i, static_cast<int>(p)}, edge.pieces()[p].bound);
  }
  for (int k = 1; k <= vertices.Extent(); ++k) {
    const int i = vertexMap_.FindIndex(vertices(k)) - 1;
    if (i < 0) continue;
    const Vec3 p = toVec(vertices_[i].point.XYZ());
    bvh.add({Feature::Vertex, i, -1}, Aabb{p, p}.inflated(margin));
  }
}

void ExactPenetration::evaluate(const FeatureRef& f, const WarmStart* warm, Search& s) const noexcept {
  double u = warm ? warm->u : 0, v = warm ? warm->v : 0;
  const double bound = s.best.distance + tie_;
  bool certain = true;
  switch (f.kind) {
    case Feature::Face: {
      FaceFoot foot, sameFace;
      const bool onThisFace = s.best.feature.kind == Feature::Face && s.best.feature.index == f.index;
      if (onThisFace) {
        sameFace.u = s.best.u;
        sameFace.v = s.best.v;
        sameFace.distance = s.best.distance;
      }
      exact::FaceStart start{warm != nullptr, u, v, nullptr};
      if (s.jet && s.jetFeature.kind == f.kind && s.jetFeature.index == f.index && s.jetFeature.piece == f.piece)
        start = {true, s.jet->u, s.jet->v, s.jet};
      const FaceSearch r = faces_[f.index].project(s.x, f.piece, start, bound, foot, onThisFace ? &sameFace : nullptr);
      s.examined.add(f, r.u, r.v);
      if (r.found && better(Feature::Face, foot.distance, s.best)) s.best = faceCandidate(f, foot);
      certain = r.certain;
      break;
    }
    case Feature::Edge: {
      EdgeFoot foot;
      const EdgeSearch r = edges_[f.index].project(s.x, f.piece, warm != nullptr, u, bound, foot);
      s.examined.add(f, u, 0);
      if (r.found && better(Feature::Edge, foot.distance, s.best)) s.best = candidate(f, foot.t, 0, foot.point, foot.distance);
      certain = r.certain;
      break;
    }
    case Feature::Vertex: {
      const double d = vertices_[f.index].point.Distance(s.x);
      if (better(Feature::Vertex, d, s.best)) s.best = candidate(f, 0, 0, vertices_[f.index].point, d);
      break;
    }
    default: break;
  }
  if (!certain) {
    if (s.unsettled.count < Search::Unsettled::kCapacity) s.unsettled.entries[s.unsettled.count++] = f;
    else s.unsettled.overflowed = true;
  }
}

// The exhaustive search of one patch or piece (the fallback), counted.
void ExactPenetration::exhaust(const FeatureRef& f, Search& s) const noexcept {
  ++s.fallbacks;
  if (s.budget <= 0) {
    s.certain = false;
    return;
  }
  const double bound = s.best.distance + tie_;
  if (f.kind == Feature::Face) {
    FaceFoot foot;
    const FaceSearch r = faces_[f.index].exhaust(s.x, f.piece, bound, foot, s.budget);
    if (r.found && better(Feature::Face, foot.distance, s.best)) s.best = faceCandidate(f, foot);
    s.certain = s.certain && r.certain;
  } else {
    EdgeFoot foot;
    const EdgeSearch r = edges_[f.index].exhaust(s.x, f.piece, bound, foot, s.budget);
    if (r.found && better(Feature::Edge, foot.distance, s.best)) s.best = candidate(f, foot.t, 0, foot.point, foot.distance);
    s.certain = s.certain && r.certain;
  }
}

// Where some Newton search was not certain (x near the focal points of a patch or piece
// for the best known then), the final best decides: every patch or piece that could still
// beat it and is not certain for it is searched exhaustively. Most were settled meanwhile
// by a closer best found later in the traversal.
void ExactPenetration::settle(const FeatureBvh& bvh, Search& s) const noexcept {
  if (!s.unsettled.any()) return;
  const Search::Unsettled list = s.unsettled;
  s.unsettled = {};
  auto settleOne = [&](const FeatureRef& f) {
    const double best = s.best.distance + tie_;
    if (f.piece >= 0 && !certainFor(f, s.x, best) && lowerBound2(f, s.x) <= best * best) exhaust(f, s);
  };
  if (!list.overflowed) {
    for (int i = 0; i < list.count; ++i) settleOne(list.entries[i]);
    return;
  }
  bvh.nearest(
      Vec3(s.x.X(), s.x.Y(), s.x.Z()), [&](const FeatureRef& f, double) { settleOne(f); },
      [&] { return (s.best.distance + tie_) * (s.best.distance + tie_); });
}

// The warm start a state holds for feature f, if any: the same patch, else the same face
// or edge (its parameters may lie in this patch too).
const WarmStart* warmStartFor(const QueryState& state, const FeatureRef& f) {
  const WarmStart* sameFeature = nullptr;
  for (const WarmStart& w : state.neighbours) {
    if (same(w, f)) return &w;
    if (!sameFeature && w.feature == f.kind && w.index == f.index + 1) sameFeature = &w;
  }
  return sameFeature;
}

void ExactPenetration::nearest(const FeatureBvh& bvh, const QueryState& state, Search& s) const noexcept {
  const Vec3 xu(s.x.X(), s.x.Y(), s.x.Z());
  // Last tick's closest feature first: its distance prunes most of the BVH.
  const FeatureRef last{state.feature, state.index - 1, state.piece};
  const WarmStart lastStart{state.feature, state.index, state.piece, state.u, state.v};
  if (state.feature != Feature::None) evaluate(last, &lastStart, s);
  bvh.nearest(
      xu,
      [&](const FeatureRef& f, double) {
        if (f.kind == last.kind && f.index == last.index && f.piece == last.piece) return;
        const WarmStart* warm = warmStartFor(state, f);
        if (!warm && state.feature == f.kind && state.index == f.index + 1) warm = &lastStart;
        evaluate(f, warm, s);
      },
      [&] { return (s.best.distance + tie_) * (s.best.distance + tie_); });
  settle(bvh, s);
}

bool ExactPenetration::insideOf(const Candidate& c, const gp_Pnt& x) const noexcept {
  return c.distance > 0 && gp_Vec(c.foot, x).Dot(outwardAt(c)) < 0;
}

Penetration ExactPenetration::query(const Vec3& xm, QueryState& state) const noexcept {
  if (!xm.allFinite()) return {};
  try {
    const Vec3 xu = xm / s_;
    Search s;
    s.x = gp_Pnt(xu.x(), xu.y(), xu.z());
    exact::SurfaceJet lastJet;
    if (state.jet.face > 0) {
      lastJet = load(state.jet);
      s.jet = &lastJet;
      s.jetFeature = {Feature::Face, state.jet.face - 1, state.jet.piece};
    }
    nearest(bvh_, state, s);
    if (s.best.feature.kind == Feature::None) return {};
    state.feature = s.best.feature.kind;
    state.index = s.best.feature.index + 1;
    state.piece = s.best.feature.piece;
    state.u = s.best.u;
    state.v = s.best.v;
    state.jet.face = 0;
    if (s.best.hasJet) store(s.best.jet, s.best.feature, state.jet);
    int n = 0;
    for (int i = 0; i < s.examined.count && n < QueryState::kNeighbours; ++i)
      if (!same(s.examined.entries[i], s.best.feature)) state.neighbours[n++] = s.examined.entries[i];
    for (; n < QueryState::kNeighbours; ++n) state.neighbours[n] = {};
    Candidate best = s.best;
    if (!solidBvhs_.empty() && s.best.feature.kind != Feature::None && !insideOf(best, s.x)) {
      // Outside the closest feature's solid: inside another one whose box holds x?
      const int own = best.feature.kind == Feature::Face ? faceSolid_[best.feature.index] : -1;
      for (std::size_t k = 0; k < solidBvhs_.size(); ++k) {
        if (static_cast<int>(k) == own || !solidBoxes_[k].contains(xu)) continue;
        Search alone;
        alone.x = s.x;
        nearest(solidBvhs_[k], QueryState{}, alone);
        s.fallbacks += alone.fallbacks;
        s.certain = s.certain && alone.certain;
        if (alone.best.feature.kind != Feature::None && insideOf(alone.best, s.x)) {
          best = alone.best;
          break;
        }
      }
    }
    Penetration p = answer(s.x, best);
    p.fallbacks = static_cast<std::uint8_t>(std::min(s.fallbacks, 255));
    p.certain = s.certain;
    return p;
  } catch (const Standard_Failure&) {
    return {};  // a surface that cannot be evaluated here: no contact rather than a crash
  }
}

// The outward direction at the candidate's foot that decides the sign.
gp_Vec ExactPenetration::outwardAt(const Candidate& c) const noexcept {
  switch (c.feature.kind) {
    case Feature::Face: return c.hasJet ? c.normal : faces_[c.feature.index].normalAt(c.u, c.v);
    case Feature::Edge: return edges_[c.feature.index].pseudoNormal(c.u, faces_);
    default: return vertices_[c.feature.index].pseudoNormal;
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
  if (c.feature.kind == Feature::Face || c.distance <= tie_) {
    p.normal = toVec(outward.XYZ()).normalized();
  } else {  // at an edge or vertex the outward normal is the direction away from the foot
    p.normal = toVec(offset.XYZ()) / c.distance;
    if (p.inside) p.normal = -p.normal;
  }
  p.feature = c.feature.kind;
  p.featureIndex = c.feature.index + 1;
  return p;
}

// The held feature alone: a face or edge searched over all its patches or pieces that
// could beat the best so far (nearest bound first is not needed: they are few).
bool ExactPenetration::queryFeature(const Vec3& xm, Feature feature, int index, double& u, double& v,
                                    Penetration& out) const noexcept {
  if (!xm.allFinite() || index < 1) return false;
  try {
    const Vec3 xu = xm / s_;
    Search s;
    s.x = gp_Pnt(xu.x(), xu.y(), xu.z());
    const WarmStart start{feature, index, -1, u, v};
    const int i = index - 1;
    // Twice over the pieces: the second time, what could still beat the best with x near
    // its focal points is searched exhaustively.
    auto visit = [&](int piece, const LeafBound& bound, bool settling) {
      const double best = s.best.distance + tie_;
      if (bound.squaredDistance(xu) > best * best) return;
      const FeatureRef f{feature, i, piece};
      if (!settling) evaluate(f, &start, s);
      else if (!certainFor(f, s.x, best)) exhaust(f, s);
    };
    // The held feature's pieces through the part's BVH, nearest bound first and pruned by
    // the best so far: a loft's face has hundreds of patches, and going over them in index
    // order cost a tick of the multi-finger method up to 3.5 ms.
    auto overPieces = [&](const auto& pieces) {
      auto pass = [&](bool settling) {
        bvh_.nearest(
            xu,
            [&](const FeatureRef& f, double) {
              if (f.kind == feature && f.index == i && f.piece >= 0 && f.piece < static_cast<int>(pieces.size()))
                visit(f.piece, pieces[static_cast<std::size_t>(f.piece)].bound, settling);
            },
            [&] { return (s.best.distance + tie_) * (s.best.distance + tie_); });
      };
      pass(false);
      if (s.unsettled.any()) pass(true);
    };
    if (feature == Feature::Face && i < static_cast<int>(faces_.size()) && faces_[i].freeform()) {
      overPieces(faces_[i].patches());
    } else if (feature == Feature::Edge && i < static_cast<int>(edges_.size()) && !edges_[i].pieces().empty()) {
      overPieces(edges_[i].pieces());
    } else if ((feature == Feature::Face && i < static_cast<int>(faces_.size())) ||
               (feature == Feature::Edge && i < static_cast<int>(edges_.size()) && edges_[i].usable()) ||
               (feature == Feature::Vertex && i < static_cast<int>(vertices_.size()))) {
      evaluate({feature, i, -1}, &start, s);
    }
    const Candidate& held = s.best;
    if (held.feature.kind == Feature::None) return false;
    u = held.u;
    v = held.v;
    out = answer(s.x, held);
    // The caller knows x is inside; the held feature's foot is deeper than the closest.
    out.inside = true;
    out.depth = held.distance * s_;
    if (held.feature.kind != Feature::Face && held.distance > tie_)
      out.normal = -toVec(gp_Vec(held.foot, s.x).XYZ()) / held.distance;
    return true;
  } catch (const Standard_Failure&) {
    return false;
  }
}

std::size_t ExactPenetration::memoryBytes() const noexcept {
  std::size_t bytes = sizeof(*this) + bvh_.memoryBytes() + vertices_.capacity() * sizeof(VertexModel);
  for (const FeatureBvh& b : solidBvhs_) bytes += b.memoryBytes();
  for (const FaceModel& f : faces_) bytes += f.memoryBytes();
  for (const EdgeModel& e : edges_) bytes += e.memoryBytes();
  return bytes;
}

}  // namespace

PenetrationModelPtr makeExactPenetration(PartModelPtr part) {
  return std::make_shared<ExactPenetration>(std::move(part));
}

}  // namespace hg::geometry
