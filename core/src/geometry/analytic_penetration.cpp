// Closed-form penetration for a part recognised as a capped cylinder, a box or a sphere:
// the cheapest rung of the ladder, and exact. The answers name the B-rep's own faces,
// edges and vertices: each analytic feature (cylinder side, top cap, top rim...; box face
// +x, edge, corner) is matched once, at build time, to the B-rep feature lying on it.
#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRep_Tool.hxx>
#include <TopoDS.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>

#include "hapticgrasp/geometry/backends.hpp"

namespace hg::geometry {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// Fixed capacities keep the model one allocation-free block. A recognised primitive has at
// most 6 faces; its B-rep usually has 3 (cylinder) or 12 (box) edges, but a CAD export may
// split an edge with extra vertices: each analytic edge then maps to several pieces.
constexpr int kMaxFaces = 6;
constexpr int kMaxEdges = 64;
constexpr int kMaxVertices = 64;
constexpr int kMaxPieces = 4;

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

// Distance from the axis: plain sqrt (std::hypot's overflow care costs more than the rest
// of a query, and part coordinates are far from overflow).
double radial(const Vec3& q) { return std::sqrt(q.x() * q.x() + q.y() * q.y()); }

// Angle in [0, 2pi).
double wrapAngle(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

// One B-rep edge covering [start, start + length] of an analytic edge's parameter: the
// coordinate along a box edge (m), or the angle about the cylinder's axis (rad).
struct Piece {
  int index = 0;
  double start = 0, length = 0;
};

struct EdgeMap {
  Piece pieces[kMaxPieces];
  int count = 0;
};

class AnalyticPenetration final : public PenetrationModel {
 public:
  explicit AnalyticPenetration(PartModelPtr part);

  std::string_view name() const noexcept override { return "analytic"; }
  std::string setting() const override;
  std::size_t memoryBytes() const noexcept override { return sizeof(*this); }
  Penetration query(const Vec3& x, QueryState& state) const noexcept override;

 protected:
  bool queryFeature(const Vec3& x, Feature feature, int index, double& u, double& v,
                    Penetration& out) const noexcept override;

 private:
  // Analytic feature ids. Cylinder faces: 0 side, 1 top cap (+z), 2 bottom cap; edges:
  // 0 top rim, 1 bottom rim. Box faces: 2k + (sign < 0) for the face normal to axis k;
  // edges: 4k + 2(sb < 0) + (sa < 0) for the edge along axis k at signs sa, sb of the
  // axes a = k+1, b = k+2 (mod 3); corners: (sx < 0) + 2(sy < 0) + 4(sz < 0). Sphere: face 0.
  static int boxFaceId(int k, double s) { return 2 * k + (s < 0); }
  static int boxEdgeId(int k, double sa, double sb) { return 4 * k + 2 * (sb < 0) + (sa < 0); }
  static int boxCornerId(double sx, double sy, double sz) { return (sx < 0) + 2 * (sy < 0) + 4 * (sz < 0); }

  Vec3 local(const Vec3& x) const { return axes_.transpose() * (x - centre_); }
  bool insideLocal(const Vec3& q) const;
  // The B-rep edge of analytic edge `id` at parameter t.
  int edgeAt(int id, double t) const;
  bool pieceContains(const Piece& p, double t) const;
  // Fills `out` from a foot and a normal in local coordinates.
  void answer(const Vec3& x, const Vec3& footLocal, const Vec3& normalLocal, double depth, Feature feature,
              int index, Penetration& out) const;
  // Against an edge or vertex foot: the sign from the solid, the normal along x - foot.
  void pointFoot(const Vec3& x, const Vec3& q, const Vec3& footLocal, const Vec3& onFootNormal, Feature feature,
                 int index, Penetration& out) const;
  Penetration closest(const Vec3& x, const Vec3& q, double& u, double& v) const;

  void matchFaces();
  void matchEdges();
  void matchVertices();

  PartModelPtr part_;
  Primitive::Kind kind_;
  Vec3 centre_;
  Mat3 axes_;
  Vec3 half_;      // box half extents
  double radius_;  // cylinder, sphere
  double halfLength_;
  double tol_ = 0;  // matching tolerance, m

  int faceIndex_[kMaxFaces] = {};          // analytic face -> B-rep face index
  EdgeMap edgeMap_[12];                    // analytic edge -> B-rep pieces
  int cornerIndex_[8] = {};                // box corner -> B-rep vertex index
  std::int8_t faceFeature_[kMaxFaces + 1];  // B-rep index -> analytic id, -1 none
  std::int8_t edgeFeature_[kMaxEdges + 1];
  std::int8_t edgePiece_[kMaxEdges + 1];
  Vec3 vertexLocal_[kMaxVertices + 1];     // B-rep vertices, local coordinates
  int nFaces_ = 0, nEdges_ = 0, nVertices_ = 0;
};

AnalyticPenetration::AnalyticPenetration(PartModelPtr part) : part_(std::move(part)) {
  const Primitive& p = part_->primitive();
  kind_ = p.kind;
  centre_ = p.centre;
  axes_ = kind_ == Primitive::Kind::Sphere ? Mat3::Identity() : p.axes;
  half_ = p.halfExtents;
  radius_ = p.radius;
  halfLength_ = p.halfLength;

  nFaces_ = part_->faces().Extent();
  nEdges_ = part_->edges().Extent();
  nVertices_ = part_->vertices().Extent();
  if (nFaces_ > kMaxFaces || nEdges_ > kMaxEdges || nVertices_ > kMaxVertices)
    throw GeometryError("analytic penetration: " + std::string(toString(kind_)) + " '" + part_->name() + "' has " +
                        std::to_string(nEdges_) + " edges and " + std::to_string(nVertices_) +
                        " vertices, more than its primitive needs");

  // Features of the primitive are apart by at least its smallest dimension; the B-rep's
  // own tolerance (imported files) may exceed a fixed relative one.
  double smallest = 0, largest = 0;
  switch (kind_) {
    case Primitive::Kind::Cylinder:
      smallest = std::min(radius_, halfLength_);
      largest = std::max(radius_, halfLength_);
      break;
    case Primitive::Kind::Box:
      smallest = half_.minCoeff();
      largest = half_.maxCoeff();
      break;
    default: smallest = largest = radius_;
  }
  const double brepTol = BRep_Tool::MaxTolerance(part_->shape(), TopAbs_EDGE) * part_->metresPerUnit();
  tol_ = std::min(0.25 * smallest, std::max(1e-7 * largest, 4 * brepTol));

  std::fill(std::begin(faceFeature_), std::end(faceFeature_), std::int8_t(-1));
  std::fill(std::begin(edgeFeature_), std::end(edgeFeature_), std::int8_t(-1));
  std::fill(std::begin(edgePiece_), std::end(edgePiece_), std::int8_t(-1));
  for (Vec3& v : vertexLocal_) v.setZero();
  matchFaces();
  matchEdges();
  matchVertices();
}

void AnalyticPenetration::matchFaces() {
  const double s = part_->metresPerUnit();
  const int expected = kind_ == Primitive::Kind::Cylinder ? 3 : kind_ == Primitive::Kind::Box ? 6 : 1;
  auto mismatch = [&](int i) {
    return GeometryError("analytic penetration: face " + std::to_string(i) + " of '" + part_->name() +
                         "' does not lie on the recognised " + toString(kind_));
  };
  for (int i = 1; i <= nFaces_; ++i) {
    BRepAdaptor_Surface surface(TopoDS::Face(part_->faces()(i)), false);
    int id = -1;
    if (surface.GetType() == GeomAbs_Plane && kind_ != Primitive::Kind::Sphere) {
      const gp_Pln plane = surface.Plane();
      const Vec3 n = axes_.transpose() * toVec(plane.Axis().Direction().XYZ());
      const Vec3 q = local(toVec(plane.Location().XYZ()) * s);
      int k = 0;
      n.cwiseAbs().maxCoeff(&k);
      if (std::abs(std::abs(n[k]) - 1) > 1e-9) throw mismatch(i);
      const double sign = q[k] < 0 ? -1 : 1;
      const double at = kind_ == Primitive::Kind::Box ? half_[k] : halfLength_;
      if (std::abs(std::abs(q[k]) - at) > tol_) throw mismatch(i);
      if (kind_ == Primitive::Kind::Box)
        id = boxFaceId(k, sign);
      else if (k == 2)
        id = sign > 0 ? 1 : 2;
    } else if (surface.GetType() == GeomAbs_Cylinder && kind_ == Primitive::Kind::Cylinder) {
      if (std::abs(surface.Cylinder().Radius() * s - radius_) <= tol_) id = 0;
    } else if (surface.GetType() == GeomAbs_Sphere && kind_ == Primitive::Kind::Sphere) {
      if (std::abs(surface.Sphere().Radius() * s - radius_) <= tol_) id = 0;
    }
    if (id < 0) throw mismatch(i);
    if (faceIndex_[id] != 0)
      throw GeometryError("analytic penetration: faces " + std::to_string(faceIndex_[id]) + " and " +
                          std::to_string(i) + " of '" + part_->name() + "' lie on the same side");
    faceIndex_[id] = i;
    faceFeature_[i] = static_cast<std::int8_t>(id);
  }
  for (int id = 0; id < expected; ++id)
    if (faceIndex_[id] == 0)
      throw GeometryError("analytic penetration: '" + part_->name() + "' lacks a face of its " + toString(kind_));
}

void AnalyticPenetration::matchEdges() {
  if (kind_ == Primitive::Kind::Sphere) return;  // a sphere's seam and poles are no features
  const double s = part_->metresPerUnit();
  constexpr int kSamples = 9;
  for (int i = 1; i <= nEdges_; ++i) {
    const TopoDS_Edge& edge = TopoDS::Edge(part_->edges()(i));
    if (BRep_Tool::Degenerated(edge)) continue;
    BRepAdaptor_Curve curve(edge);
    const double t0 = curve.FirstParameter(), t1 = curve.LastParameter();
    Vec3 q[kSamples];
    for (int j = 0; j < kSamples; ++j) q[j] = local(toVec(curve.Value(t0 + (t1 - t0) * j / (kSamples - 1)).XYZ()) * s);
    int id = -1;
    Piece piece{i, 0, 0};
    if (kind_ == Primitive::Kind::Cylinder) {
      const double sz = q[0].z() < 0 ? -1 : 1;
      bool onRim = true;
      for (const Vec3& p : q)
        onRim = onRim && std::abs(radial(p) - radius_) <= tol_ && std::abs(p.z() - sz * halfLength_) <= tol_;
      if (!onRim) continue;  // the seam
      id = sz > 0 ? 0 : 1;
      // Unwrap the samples' angles: the arc runs from the first one by `turn` radians.
      double turn = 0;
      for (int j = 1; j < kSamples; ++j) {
        double step = std::atan2(q[j].y(), q[j].x()) - std::atan2(q[j - 1].y(), q[j - 1].x());
        if (step > std::numbers::pi) step -= kTwoPi;
        if (step < -std::numbers::pi) step += kTwoPi;
        turn += step;
      }
      const double first = std::atan2(q[0].y(), q[0].x());
      piece.start = wrapAngle(turn >= 0 ? first : first + turn);
      piece.length = std::min(std::abs(turn), kTwoPi);
    } else {
      for (int k = 0; k < 3 && id < 0; ++k) {
        const int a = (k + 1) % 3, b = (k + 2) % 3;
        const double sa = q[0][a] < 0 ? -1 : 1, sb = q[0][b] < 0 ? -1 : 1;
        bool onEdge = true;
        for (const Vec3& p : q)
          onEdge = onEdge && std::abs(p[a] - sa * half_[a]) <= tol_ && std::abs(p[b] - sb * half_[b]) <= tol_;
        if (!onEdge) continue;
        id = boxEdgeId(k, sa, sb);
        piece.start = std::min(q[0][k], q[kSamples - 1][k]);
        piece.length = std::abs(q[kSamples - 1][k] - q[0][k]);
      }
      if (id < 0)
        throw GeometryError("analytic penetration: edge " + std::to_string(i) + " of '" + part_->name() +
                            "' does not lie on an edge of the recognised box");
    }
    EdgeMap& map = edgeMap_[id];
    if (map.count == kMaxPieces)
      throw GeometryError("analytic penetration: an edge of '" + part_->name() + "' is split into more than " +
                          std::to_string(kMaxPieces) + " pieces");
    edgePiece_[i] = static_cast<std::int8_t>(map.count);
    map.pieces[map.count++] = piece;
    edgeFeature_[i] = static_cast<std::int8_t>(id);
  }
  // Every analytic edge must be covered by its pieces.
  const int count = kind_ == Primitive::Kind::Cylinder ? 2 : 12;
  for (int id = 0; id < count; ++id) {
    const double full = kind_ == Primitive::Kind::Cylinder ? kTwoPi : 2 * half_[id / 4];
    const double slack = kind_ == Primitive::Kind::Cylinder ? 1e-6 + 2 * tol_ / radius_ : 2 * tol_;
    double covered = 0;
    for (int j = 0; j < edgeMap_[id].count; ++j) covered += edgeMap_[id].pieces[j].length;
    if (edgeMap_[id].count == 0 || std::abs(covered - full) > slack)
      throw GeometryError("analytic penetration: the edges of '" + part_->name() + "' do not cover its " +
                          toString(kind_) + "'s " + (kind_ == Primitive::Kind::Cylinder ? "rims" : "edges"));
  }
}

void AnalyticPenetration::matchVertices() {
  const double s = part_->metresPerUnit();
  for (int i = 1; i <= nVertices_; ++i)
    vertexLocal_[i] = local(toVec(BRep_Tool::Pnt(TopoDS::Vertex(part_->vertices()(i))).XYZ()) * s);
  if (kind_ != Primitive::Kind::Box) return;
  for (int i = 1; i <= nVertices_; ++i) {
    const Vec3& q = vertexLocal_[i];
    if (((q.cwiseAbs() - half_).cwiseAbs().array() <= tol_).all()) cornerIndex_[boxCornerId(q.x(), q.y(), q.z())] = i;
  }
  for (int c = 0; c < 8; ++c)
    if (cornerIndex_[c] == 0)
      throw GeometryError("analytic penetration: '" + part_->name() + "' lacks a corner of its box");
}

std::string AnalyticPenetration::setting() const {
  char text[96];
  switch (kind_) {
    case Primitive::Kind::Cylinder:
      std::snprintf(text, sizeof text, "cylinder r %g mm, length %g mm", radius_ * 1e3, 2 * halfLength_ * 1e3);
      break;
    case Primitive::Kind::Box:
      std::snprintf(text, sizeof text, "box %g x %g x %g mm", 2 * half_.x() * 1e3, 2 * half_.y() * 1e3,
                    2 * half_.z() * 1e3);
      break;
    default: std::snprintf(text, sizeof text, "sphere r %g mm", radius_ * 1e3);
  }
  return text;
}

bool AnalyticPenetration::insideLocal(const Vec3& q) const {
  switch (kind_) {
    case Primitive::Kind::Cylinder:
      return radial(q) < radius_ && std::abs(q.z()) < halfLength_;
    case Primitive::Kind::Box: return (q.cwiseAbs().array() < half_.array()).all();
    default: return q.norm() < radius_;
  }
}

bool AnalyticPenetration::pieceContains(const Piece& p, double t) const {
  if (kind_ == Primitive::Kind::Cylinder) {
    const double slack = 1e-9 + tol_ / radius_;
    const double rel = wrapAngle(t - p.start);
    return rel <= p.length + slack || kTwoPi - rel <= slack;
  }
  return t >= p.start - tol_ && t <= p.start + p.length + tol_;
}

int AnalyticPenetration::edgeAt(int id, double t) const {
  const EdgeMap& map = edgeMap_[id];
  if (map.count == 1) return map.pieces[0].index;
  for (int j = 0; j < map.count; ++j)
    if (pieceContains(map.pieces[j], t)) return map.pieces[j].index;
  return map.pieces[0].index;  // unreachable: the pieces cover the edge
}

void AnalyticPenetration::answer(const Vec3& x, const Vec3& footLocal, const Vec3& normalLocal, double depth,
                                 Feature feature, int index, Penetration& out) const {
  out.inside = depth > 0;
  out.depth = depth;
  out.foot = centre_ + axes_ * footLocal;
  out.vector = x - out.foot;
  out.normal = axes_ * normalLocal;
  out.feature = feature;
  out.featureIndex = index;
}

void AnalyticPenetration::pointFoot(const Vec3& x, const Vec3& q, const Vec3& footLocal, const Vec3& onFootNormal,
                                    Feature feature, int index, Penetration& out) const {
  const Vec3 d = q - footLocal;
  const double length = d.norm();
  const bool inside = insideLocal(q);
  const Vec3 n = length > 0 ? Vec3((inside ? -d : d) / length) : onFootNormal;
  answer(x, footLocal, n, inside ? length : -length, feature, index, out);
}

Penetration AnalyticPenetration::closest(const Vec3& x, const Vec3& q, double& u, double& v) const {
  Penetration out;
  switch (kind_) {
    case Primitive::Kind::Cylinder: {
      const double R = radius_, H = halfLength_;
      const double rho = radial(q);
      // On the axis every side point is as close: take the local x direction.
      const double cx = rho > 0 ? q.x() / rho : 1, cy = rho > 0 ? q.y() / rho : 0;
      const double dr = rho - R, dz = std::abs(q.z()) - H;
      const double sz = q.z() < 0 ? -1 : 1;
      if (dr > 0 && dz > 0) {  // outside, beyond a rim
        const Vec3 foot(R * cx, R * cy, sz * H);
        const Vec3 d = q - foot;
        const double length = d.norm();
        u = std::atan2(cy, cx);
        v = 0;
        answer(x, foot, d / length, -length, Feature::Edge, edgeAt(sz > 0 ? 0 : 1, u), out);
      } else if (dr > dz) {  // the side is closer (inside) or the only one x faces (outside)
        u = std::atan2(cy, cx);
        v = q.z();
        answer(x, Vec3(R * cx, R * cy, q.z()), Vec3(cx, cy, 0), -dr, Feature::Face, faceIndex_[0], out);
      } else {  // a cap
        u = q.x();
        v = q.y();
        answer(x, Vec3(q.x(), q.y(), sz * H), Vec3(0, 0, sz), -dz, Feature::Face, faceIndex_[sz > 0 ? 1 : 2], out);
      }
      return out;
    }
    case Primitive::Kind::Box: {
      const Vec3 d = q.cwiseAbs() - half_;
      int outside = 0;
      for (int k = 0; k < 3; ++k) outside += d[k] > 0;
      if (outside <= 1) {  // a face: inside, the nearest; outside, the one x faces
        int k = 0;
        d.maxCoeff(&k);
        const double sign = q[k] < 0 ? -1 : 1;
        Vec3 foot = q, n = Vec3::Zero();
        foot[k] = sign * half_[k];
        n[k] = sign;
        u = q[(k + 1) % 3];
        v = q[(k + 2) % 3];
        answer(x, foot, n, -d[k], Feature::Face, faceIndex_[boxFaceId(k, sign)], out);
        return out;
      }
      const Vec3 foot = q.cwiseMax(-half_).cwiseMin(half_);
      const Vec3 e = q - foot;
      const double length = e.norm();
      if (outside == 3) {
        u = v = 0;
        answer(x, foot, e / length, -length, Feature::Vertex, cornerIndex_[boxCornerId(q.x(), q.y(), q.z())], out);
        return out;
      }
      int k = 0;  // the edge runs along the axis x is within
      d.minCoeff(&k);
      const int a = (k + 1) % 3, b = (k + 2) % 3;
      u = q[k];
      v = 0;
      answer(x, foot, e / length, -length, Feature::Edge, edgeAt(boxEdgeId(k, q[a], q[b]), u), out);
      return out;
    }
    default: {
      const double r = q.norm();
      const Vec3 n = r > 0 ? Vec3(q / r) : Vec3::UnitX();  // at the centre any foot will do
      u = std::atan2(n.y(), n.x());
      v = n.z();
      answer(x, radius_ * n, n, radius_ - r, Feature::Face, faceIndex_[0], out);
      return out;
    }
  }
}

Penetration AnalyticPenetration::query(const Vec3& x, QueryState& state) const noexcept {
  double u = 0, v = 0;
  const Penetration out = closest(x, local(x), u, v);
  state.feature = out.feature;
  state.index = out.featureIndex;
  state.u = u;
  state.v = v;
  return out;
}

bool AnalyticPenetration::queryFeature(const Vec3& x, Feature feature, int index, double& u, double& v,
                                       Penetration& out) const noexcept {
  const Vec3 q = local(x);
  switch (feature) {
    case Feature::Face: {
      if (index < 1 || index > nFaces_ || faceFeature_[index] < 0) return false;
      const int id = faceFeature_[index];
      if (kind_ == Primitive::Kind::Sphere) {
        out = closest(x, q, u, v);
        return true;
      }
      if (kind_ == Primitive::Kind::Cylinder) {
        const double R = radius_, H = halfLength_;
        const double rho = radial(q);
        if (id == 0) {  // radial projection onto the side, within the caps
          if (std::abs(q.z()) > H) return false;
          const double cx = rho > 0 ? q.x() / rho : std::cos(u), cy = rho > 0 ? q.y() / rho : std::sin(u);
          u = std::atan2(cy, cx);
          v = q.z();
          answer(x, Vec3(R * cx, R * cy, q.z()), Vec3(cx, cy, 0), R - rho, Feature::Face, index, out);
          return true;
        }
        if (rho > R) return false;  // a cap: within the rim
        const double sz = id == 1 ? 1 : -1;
        u = q.x();
        v = q.y();
        answer(x, Vec3(q.x(), q.y(), sz * H), Vec3(0, 0, sz), H - sz * q.z(), Feature::Face, index, out);
        return true;
      }
      const int k = id / 2, a = (k + 1) % 3, b = (k + 2) % 3;  // a box face
      const double sign = id % 2 ? -1 : 1;
      if (std::abs(q[a]) > half_[a] || std::abs(q[b]) > half_[b]) return false;
      Vec3 foot = q, n = Vec3::Zero();
      foot[k] = sign * half_[k];
      n[k] = sign;
      u = q[a];
      v = q[b];
      answer(x, foot, n, half_[k] - sign * q[k], Feature::Face, index, out);
      return true;
    }
    case Feature::Edge: {
      if (index < 1 || index > nEdges_ || edgeFeature_[index] < 0) return false;
      const int id = edgeFeature_[index];
      const Piece& piece = edgeMap_[id].pieces[edgePiece_[index]];
      if (kind_ == Primitive::Kind::Cylinder) {  // the closest point of the rim circle
        const double R = radius_, sz = id == 0 ? 1 : -1;
        const double rho = radial(q);
        const double cx = rho > 0 ? q.x() / rho : std::cos(u), cy = rho > 0 ? q.y() / rho : std::sin(u);
        const double angle = std::atan2(cy, cx);
        if (edgeMap_[id].count > 1 && !pieceContains(piece, angle)) return false;
        u = angle;
        v = 0;
        pointFoot(x, q, Vec3(R * cx, R * cy, sz * halfLength_), Vec3(cx, cy, sz).normalized(), Feature::Edge, index, out);
        return true;
      }
      const int k = id / 4, a = (k + 1) % 3, b = (k + 2) % 3;  // a box edge segment
      const double sa = id & 1 ? -1 : 1, sb = id & 2 ? -1 : 1;
      if (std::abs(q[k]) > half_[k] || q[k] < piece.start - tol_ || q[k] > piece.start + piece.length + tol_)
        return false;
      Vec3 foot, n = Vec3::Zero();
      foot[k] = q[k];
      foot[a] = sa * half_[a];
      foot[b] = sb * half_[b];
      n[a] = sa;
      n[b] = sb;
      u = q[k];
      v = 0;
      pointFoot(x, q, foot, n.normalized(), Feature::Edge, index, out);
      return true;
    }
    case Feature::Vertex: {
      if (index < 1 || index > nVertices_) return false;
      const Vec3& foot = vertexLocal_[index];
      Vec3 onFoot = Vec3::UnitZ();
      if (q == foot) {  // on the vertex itself: the normal the closest answer gives there
        double cu = 0, cv = 0;
        onFoot = axes_.transpose() * closest(x, q, cu, cv).normal;
      }
      u = v = 0;
      pointFoot(x, q, foot, onFoot, Feature::Vertex, index, out);
      return true;
    }
    default: return false;
  }
}

}  // namespace

PenetrationModelPtr makeAnalyticPenetration(PartModelPtr part) {
  if (!part) throw GeometryError("analytic penetration: no part");
  if (part->primitive().kind == Primitive::Kind::None)
    throw GeometryError("analytic penetration: part '" + part->name() +
                        "' is not recognised as a cylinder, box or sphere");
  return std::make_shared<AnalyticPenetration>(std::move(part));
}

}  // namespace hg::geometry
