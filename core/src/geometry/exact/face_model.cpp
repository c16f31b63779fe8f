#include "face_model.hpp"

#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <ElSLib.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <Geom_BSplineSurface.hxx>
#include <gp_Pnt2d.hxx>

#include <algorithm>
#include <cmath>

namespace hg::geometry::exact {
namespace {

// Brings t into [lo, lo + period).
double wrap(double t, double lo, double period) {
  const double k = std::floor((t - lo) / period);
  return t - k * period;
}

bool isClosedForm(GeomAbs_SurfaceType type) {
  return type == GeomAbs_Plane || type == GeomAbs_Cylinder || type == GeomAbs_Sphere;
}

}  // namespace

FaceModel::FaceModel(const TopoDS_Face& face, double characteristicLength)
    : surface_(BRep_Tool::Surface(face)),
      evaluator_(surface_),
      reversed_(face.Orientation() == TopAbs_REVERSED),
      tolerance_(std::max(BRep_Tool::Tolerance(face), 1e-12 * characteristicLength)),
      domain_(face) {
  GeomAdaptor_Surface adaptor(surface_);
  type_ = adaptor.GetType();
  if (type_ == GeomAbs_Plane) plane_ = adaptor.Plane();
  if (type_ == GeomAbs_Cylinder) cylinder_ = adaptor.Cylinder();
  if (type_ == GeomAbs_Sphere) sphere_ = adaptor.Sphere();
  if (type_ == GeomAbs_Cone) cone_ = adaptor.Cone();
  if (type_ == GeomAbs_Torus) torus_ = adaptor.Torus();
  BRepTools::UVBounds(face, u0_, u1_, v0_, v1_);

  // A face with a seam spans a whole closed direction and wraps there (a cylinder's side;
  // a loft through closed sections, whose B-spline surface OCCT may not even flag as
  // closed). A face on part of a periodic surface (a fillet) is clamped to its own range
  // after bringing u into it.
  if (surface_->IsUPeriodic()) uPeriod_ = surface_->UPeriod();
  if (surface_->IsVPeriodic()) vPeriod_ = surface_->VPeriod();
  for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More(); ex.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(ex.Current());
    if (!BRep_Tool::IsClosed(edge, face)) continue;
    double f, l;
    const Handle(Geom2d_Curve) a = BRep_Tool::CurveOnSurface(TopoDS::Edge(edge.Oriented(TopAbs_FORWARD)), face, f, l);
    const Handle(Geom2d_Curve) b = BRep_Tool::CurveOnSurface(TopoDS::Edge(edge.Oriented(TopAbs_REVERSED)), face, f, l);
    if (a.IsNull() || b.IsNull()) continue;
    const gp_Pnt2d pa = a->Value(0.5 * (f + l)), pb = b->Value(0.5 * (f + l));
    if (std::abs(pa.X() - pb.X()) > std::abs(pa.Y() - pb.Y())) {
      if (uPeriod_ == 0) uPeriod_ = u1_ - u0_;
    } else if (vPeriod_ == 0) {
      vPeriod_ = v1_ - v0_;
    }
  }

  if (!isClosedForm(type_) && type_ != GeomAbs_Cone && type_ != GeomAbs_Torus) buildSeeds(face);
}

// A grid over the face's UV box, kept where it falls inside the trimmed face: the start of
// a cold search is the seed nearest to the point. Denser for surfaces with more poles.
void FaceModel::buildSeeds(const TopoDS_Face&) {
  int nu = 24, nv = 24;
  if (auto bs = Handle(Geom_BSplineSurface)::DownCast(surface_); !bs.IsNull()) {
    nu = std::clamp(3 * bs->NbUPoles() + 8, 16, 64);
    nv = std::clamp(3 * bs->NbVPoles() + 8, 16, 64);
  }
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = u0_ + (u1_ - u0_) * (i + 0.5) / nu;
      const double v = v0_ + (v1_ - v0_) * (j + 0.5) / nv;
      if (insideTrimmedFace(u, v)) seeds_.push_back({u, v, surface_->Value(u, v)});
    }
  if (seeds_.empty()) {  // a sliver: fall back to the centre of the UV box
    const double u = 0.5 * (u0_ + u1_), v = 0.5 * (v0_ + v1_);
    seeds_.push_back({u, v, surface_->Value(u, v)});
  }
}

bool FaceModel::closedForm(const gp_Pnt& x, double& u, double& v) const noexcept {
  switch (type_) {
    case GeomAbs_Plane: ElSLib::Parameters(plane_, x, u, v); return true;
    case GeomAbs_Cylinder: ElSLib::Parameters(cylinder_, x, u, v); return true;
    case GeomAbs_Sphere: ElSLib::Parameters(sphere_, x, u, v); return true;
    default: return false;
  }
}

void FaceModel::nearestSeed(const gp_Pnt& x, double& u, double& v) const noexcept {
  double best = INFINITY;
  for (const SurfaceSeed& s : seeds_) {
    const double d = s.point.SquareDistance(x);
    if (d < best) {
      best = d;
      u = s.u;
      v = s.v;
    }
  }
}

bool FaceModel::wrapOrClamp(double& u, double& v) const noexcept {
  bool inside = true;
  // Wrapping maps exactly into [lo, lo + period): a value a hair below a seam must come
  // out just below its far side, or the domain test sees it beyond both seams.
  auto fit = [&inside](double& t, double lo, double hi, double period) {
    const double slack = 1e-12 * std::max(1.0, hi - lo);
    if (period > 0) {
      t = wrap(t, lo, period);
      if (t <= hi + slack) return;
      // Beyond the face's range on a periodic surface: clamp to the nearer end.
      const double pastHi = t - hi, beforeLo = lo + period - t;
      t = pastHi < beforeLo ? hi : lo;
      inside = false;
      return;
    }
    if (t < lo - slack) t = lo, inside = false;
    if (t > hi + slack) t = hi, inside = false;
  };
  fit(u, u0_, u1_, uPeriod_);
  fit(v, v0_, v1_, vPeriod_);
  return inside;
}

// Minimises |S(u,v) - x|^2 with Newton on the exact second derivatives, falling back to
// Gauss-Newton where the Hessian is not positive definite. A step that made the distance
// grow is halved (checked with the next evaluation, which Newton needs anyway). Clamps
// (or wraps) to the face's UV box; pushing against the box twice in a row means the
// closest point of the face is on its boundary, which an edge or vertex answers for.
bool FaceModel::newton(const gp_Pnt& x, double& u, double& v) const noexcept {
  gp_Pnt S;
  gp_Vec Su, Sv, Suu, Svv, Suv;
  const double maxStepU = 0.25 * (u1_ - u0_), maxStepV = 0.25 * (v1_ - v0_);
  double uPrev = u, vPrev = v, fPrev = INFINITY, du = 0, dv = 0;
  int clamped = 0, clampedTotal = 0;
  for (int iteration = 0; iteration < 40; ++iteration) {
    evaluator_.d2(u, v, S, Su, Sv, Suu, Svv, Suv);
    const gp_Vec r(x, S);
    const double f = r.SquareMagnitude();
    // Overshot: back up half way. Near the minimum f changes by rounding only; such a
    // change is no overshoot (treating it as one halved the step forever).
    if (f > fPrev * (1 + 1e-12) + 1e-30) {
      // A clamped step that made things worse: the minimum is on the boundary (an edge's).
      if (clamped > 0) return false;
      du *= 0.5;
      dv *= 0.5;
      if ((std::abs(du) * std::sqrt(Su.SquareMagnitude()) + std::abs(dv) * std::sqrt(Sv.SquareMagnitude())) <
          1e-3 * tolerance_) {
        u = uPrev;
        v = vPrev;
        return clamped == 0;
      }
      u = uPrev + du;
      v = vPrev + dv;
      wrapOrClamp(u, v);
      continue;
    }
    const double gu = r.Dot(Su), gv = r.Dot(Sv);
    const double guu = Su.Dot(Su), gvv = Sv.Dot(Sv), guv = Su.Dot(Sv);
    double a = guu + r.Dot(Suu), b = guv + r.Dot(Suv), c = gvv + r.Dot(Svv);
    double det = a * c - b * b;
    if (!(a > 0 && det > 1e-14 * guu * gvv)) {  // not a minimum locally: Gauss-Newton
      a = guu * (1 + 1e-9);
      b = guv;
      c = gvv * (1 + 1e-9);
      det = a * c - b * b;
      if (!(det > 0)) return false;  // singular point (a pole): give up on this face
    }
    du = std::clamp(-(c * gu - b * gv) / det, -maxStepU, maxStepU);
    dv = std::clamp(-(a * gv - b * gu) / det, -maxStepV, maxStepV);
    uPrev = u;
    vPrev = v;
    fPrev = f;
    u += du;
    v += dv;
    // Pushing against the UV box twice in a row, or three times at all: the closest
    // point of the face is on its boundary.
    if (!wrapOrClamp(u, v)) {
      ++clampedTotal;
      if (++clamped == 2 || clampedTotal == 3) return false;
    } else {
      clamped = 0;
    }
    const double step = std::abs(du) * std::sqrt(guu) + std::abs(dv) * std::sqrt(gvv);
    if (step < 1e-3 * tolerance_) return clamped == 0;
  }
  return clamped == 0;
}

bool FaceModel::insideTrimmedFace(double u, double v) const noexcept {
  return domain_.contains(u, v);
}

gp_Vec FaceModel::normalAt(double u, double v) const noexcept {
  gp_Pnt p;
  gp_Vec du, dv;
  evaluator_.d1(u, v, p, du, dv);
  gp_Vec n = du.Crossed(dv);
  if (n.SquareMagnitude() < 1e-24 * du.SquareMagnitude() * dv.SquareMagnitude() || n.SquareMagnitude() == 0) {
    // A pole (sphere, cone apex): the normal of a point just inside the UV box.
    const double nu = u + 1e-6 * (0.5 * (u0_ + u1_) - u), nv = v + 1e-6 * (0.5 * (v0_ + v1_) - v);
    evaluator_.d1(nu, nv, p, du, dv);
    n = du.Crossed(dv);
  }
  const double m = n.Magnitude();
  if (m > 0) n /= m;
  return reversed_ ? n.Reversed() : n;
}

bool FaceModel::project(const gp_Pnt& x, bool warm, double& u, double& v, double bound,
                        FaceFoot& foot) const noexcept {
  if (!closedForm(x, u, v)) {
    if (!warm) {
      // Cones and tori: the parameters of x itself start Newton near the foot.
      if (type_ == GeomAbs_Cone) ElSLib::Parameters(cone_, x, u, v);
      else if (type_ == GeomAbs_Torus) ElSLib::Parameters(torus_, x, u, v);
      else nearestSeed(x, u, v);
    }
    if (!newton(x, u, v)) return false;
  }
  if (!wrapOrClamp(u, v)) return false;  // the surface's foot lies beyond the face
  const gp_Pnt p = evaluator_.value(u, v);
  const double d = p.Distance(x);
  if (d >= bound) return false;          // cannot beat what we have: skip the classifier
  if (!insideTrimmedFace(u, v)) return false;
  foot.u = u;
  foot.v = v;
  foot.point = p;
  foot.distance = d;
  foot.normal = normalAt(u, v);
  return true;
}

std::size_t FaceModel::memoryBytes() const noexcept {
  return sizeof(*this) + seeds_.capacity() * sizeof(SurfaceSeed) + domain_.memoryBytes() + evaluator_.memoryBytes();
}

}  // namespace hg::geometry::exact
