#include "face_model.hpp"

#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomConvert.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SurfaceOfLinearExtrusion.hxx>
#include <Geom_SurfaceOfRevolution.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <gp_Pnt2d.hxx>

#include <algorithm>
#include <cmath>

#include "patch_search.hpp"

namespace hg::geometry::exact {
namespace {

// Brings t into [lo, lo + period). A t a hair below lo (atan2 of a point 1e-18 m off a
// seam's plane) rounds to lo + period exactly, the far seam itself, where the domain test
// sees it beyond both seams and the face is lost: it is kept one ulp below instead.
double wrap(double t, double lo, double period) {
  const double k = std::floor((t - lo) / period);
  const double w = t - k * period;
  return w < lo + period ? w : std::nextafter(lo + period, lo);
}

// The surface without rectangular trims (the face's own trim does the trimming), and an
// offset surface with a canonical equivalent (of a plane, cylinder, ...) as that.
Handle(Geom_Surface) untrimmed(Handle(Geom_Surface) s) {
  for (;;) {
    if (auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(s); !t.IsNull()) {
      s = t->BasisSurface();
    } else if (auto o = Handle(Geom_OffsetSurface)::DownCast(s); !o.IsNull() && !o->Surface().IsNull()) {
      s = o->Surface();
    } else {
      return s;
    }
  }
}

// What Newton searches on a face: its surface, or the basis of an offset surface, and
// how far the surface stands off it.
double offsetOf(const Handle(Geom_Surface)& s) {
  const auto o = Handle(Geom_OffsetSurface)::DownCast(s);
  return o.IsNull() ? 0 : o->Offset();
}
Handle(Geom_Surface) searchedBasis(const Handle(Geom_Surface)& s) {
  const auto o = Handle(Geom_OffsetSurface)::DownCast(s);
  return o.IsNull() ? s : untrimmed(o->BasisSurface());
}

// What to evaluate: a Bézier surface as the B-spline it is (one span), for the span cache.
Handle(Geom_Surface) evaluable(const Handle(Geom_Surface)& s) {
  if (auto bezier = Handle(Geom_BezierSurface)::DownCast(s); !bezier.IsNull())
    return GeomConvert::SurfaceToBSplineSurface(bezier);
  return s;
}

std::vector<double> curveKnots(Handle(Geom_Curve) c) {
  while (auto t = Handle(Geom_TrimmedCurve)::DownCast(c)) c = t->BasisCurve();
  std::vector<double> k;
  if (auto bs = Handle(Geom_BSplineCurve)::DownCast(c); !bs.IsNull())
    for (int i = 1; i <= bs->NbKnots(); ++i) k.push_back(bs->Knot(i));
  return k;
}

// Where the surface's derivatives may jump: patches never straddle these.
void knotBreaks(const Handle(Geom_Surface)& s, std::vector<double>& u, std::vector<double>& v) {
  if (auto bs = Handle(Geom_BSplineSurface)::DownCast(s); !bs.IsNull()) {
    for (int i = 1; i <= bs->NbUKnots(); ++i) u.push_back(bs->UKnot(i));
    for (int i = 1; i <= bs->NbVKnots(); ++i) v.push_back(bs->VKnot(i));
  } else if (auto rev = Handle(Geom_SurfaceOfRevolution)::DownCast(s); !rev.IsNull()) {
    v = curveKnots(rev->BasisCurve());
  } else if (auto ext = Handle(Geom_SurfaceOfLinearExtrusion)::DownCast(s); !ext.IsNull()) {
    u = curveKnots(ext->BasisCurve());
  } else if (auto off = Handle(Geom_OffsetSurface)::DownCast(s); !off.IsNull()) {
    knotBreaks(untrimmed(off->BasisSurface()), u, v);
  }
}

bool isClosedForm(GeomAbs_SurfaceType type) {
  return type == GeomAbs_Plane || type == GeomAbs_Cylinder || type == GeomAbs_Sphere || type == GeomAbs_Cone ||
         type == GeomAbs_Torus;
}

}  // namespace

FaceModel::FaceModel(const TopoDS_Face& face, double characteristicLength)
    : surface_(untrimmed(BRep_Tool::Surface(face))),
      offset_(offsetOf(surface_)),
      basis_(searchedBasis(surface_)),
      evaluator_(evaluable(basis_)),
      reversed_(face.Orientation() == TopAbs_REVERSED),
      tolerance_(std::max(BRep_Tool::Tolerance(face), 1e-12 * characteristicLength)),
      precision_(1e-9 * characteristicLength),
      accuracy_(1e-9 * characteristicLength),
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
  uPeriodic_ = surface_->IsUPeriodic();
  vPeriodic_ = surface_->IsVPeriodic();
  if (uPeriodic_) uPeriod_ = surface_->UPeriod();
  if (vPeriodic_) vPeriod_ = surface_->VPeriod();
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
  if (!isClosedForm(type_)) buildPatches();
}

void FaceModel::buildPatches() {
  std::vector<double> uBreaks, vBreaks;
  knotBreaks(basis_, uBreaks, vBreaks);
  // A periodic direction without knots is cut in quarters: a patch never wraps round.
  if (uBreaks.empty() && uPeriod_ > 0)
    for (int k = 1; k < 4; ++k) uBreaks.push_back(u0_ + k * (u1_ - u0_) / 4);
  if (vBreaks.empty() && vPeriod_ > 0)
    for (int k = 1; k < 4; ++k) vBreaks.push_back(v0_ + k * (v1_ - v0_) / 4);
  PatchOptions options;
  options.tolerance = tolerance_;
  // Cut on what Newton searches (the basis of an offset surface); the offset surface lies
  // within |d| of it.
  const Basis basis{this};
  patches_ = buildSurfacePatches(
      [&basis](double u, double v, gp_Pnt& p, gp_Vec& du, gp_Vec& dv, gp_Vec& duu, gp_Vec& dvv, gp_Vec& duv) {
        basis.d2(u, v, p, du, dv, duu, dvv, duv);
      },
      {u0_, u1_, v0_, v1_}, uBreaks, vBreaks, options);
  if (offset_ != 0)
    for (SurfacePatch& p : patches_) growForOffset(p);
}

// A patch of an offset surface's basis made to bound the offset surface: its bounds grow by
// |d|, its second derivatives by the normal's turning (d N_uu is about d k |S_u|^2... with
// the sampled margins). Its spread and curvature stay the basis's: the focal tests are
// made on the basis, at the distance from it.
void FaceModel::growForOffset(SurfacePatch& p) const {
  const double d = std::abs(offset_), k = std::max(p.kTowards, p.kAway);
  p.bound.box = p.bound.box.inflated(d);
  if (p.bound.oriented()) {
    // Every normal is within `turn` of the axis: the offset moves a point d along the
    // axis, give or take d (1 - cos turn), and d sin turn across it.
    const double turn = std::min(1.1 * p.turn + 0.01, M_PI / 2);  // sampled: with a margin
    const double across = d * std::sin(turn), along = d * (1 - std::cos(turn));
    p.bound.centre += offset_ * Vec3(p.bound.axes.col(2));
    p.bound.half += Vec3(across, across, along);
  }
  const double grow = 1 + 2 * d * k;
  p.maxSuu *= grow;
  p.maxSuv *= grow;
  p.maxSvv *= grow;
  p.lipschitzU *= grow;
  p.lipschitzV *= grow;
}

gp_Pnt FaceModel::value(double u, double v) const noexcept {
  if (offset_ == 0) return evaluator_.value(wrapU(u), wrapV(v));
  gp_Pnt p;
  gp_Vec du, dv;
  evaluator_.d1(wrapU(u), wrapV(v), p, du, dv);
  gp_Vec n = du.Crossed(dv);
  const double m = n.Magnitude();
  return m > 0 ? p.Translated(n * (offset_ / m)) : surface_->Value(wrapU(u), wrapV(v));
}

void FaceModel::d2(double u, double v, gp_Pnt& p, gp_Vec& du, gp_Vec& dv, gp_Vec& duu, gp_Vec& dvv,
                   gp_Vec& duv) const noexcept {
  if (offset_ == 0) evaluator_.d2(wrapU(u), wrapV(v), p, du, dv, duu, dvv, duv);
  else surface_->D2(wrapU(u), wrapV(v), p, du, dv, duu, dvv, duv);  // slow, uncached: the fallback only
}

double FaceModel::wrapClosed(double t, double lo, double period, bool periodic) noexcept {
  return period > 0 && !periodic ? wrap(t, lo, period) : t;
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

bool FaceModel::accept(const gp_Pnt& x, double u, double v, double bound, FaceFoot& foot,
                       const gp_Pnt* point) const noexcept {
  if (!wrapOrClamp(u, v)) return false;  // the surface's foot lies beyond the face
  const gp_Pnt p = point ? *point : value(u, v);
  const double d = p.Distance(x);
  if (d >= bound) return false;  // cannot beat what we have: skip the domain test
  if (!domain_.contains(u, v)) return false;
  foot.u = u;
  foot.v = v;
  foot.point = p;
  foot.distance = d;
  foot.hasJet = false;
  return true;
}

SurfaceFeet FaceModel::closedFormFeet(const gp_Pnt& x) const noexcept {
  switch (type_) {
    case GeomAbs_Plane: return planeFeet(plane_, x);
    case GeomAbs_Cylinder: return cylinderFeet(cylinder_, x);
    case GeomAbs_Sphere: return sphereFeet(sphere_, x);
    case GeomAbs_Cone: return coneFeet(cone_, x);
    default: return torusFeet(torus_, x);
  }
}

// Every local minimum of the distance on the surface is listed: the face's foot is the
// closest of those inside it (or lies on its boundary). Exact: always certain.
FaceSearch FaceModel::projectClosedForm(const gp_Pnt& x, double bound, FaceFoot& foot) const noexcept {
  const SurfaceFeet feet = closedFormFeet(x);
  FaceSearch search;
  for (int k = 0; k < feet.count; ++k) {
    // x on the axis: every meridian is as close; the middle one is likeliest in the face.
    const double cu = feet.anyU ? 0.5 * (u0_ + u1_) : feet.u[k], cv = feet.anyV ? 0.5 * (v0_ + v1_) : feet.v[k];
    if (k == 0) search.u = cu, search.v = cv;
    if (accept(x, cu, cv, bound, foot)) {
      search.found = true;
      bound = foot.distance;
      search.u = foot.u;
      search.v = foot.v;
    }
  }
  return search;
}

// The rectangle Newton may roam on a patch: the patch and a margin, so that a foot on the
// border between two patches lies inside one search; across a closed direction the
// margin wraps, elsewhere the face's box stops it.
UvRect FaceModel::searchRect(const SurfacePatch& patch) const noexcept {
  const UvRect& r = patch.rect;
  const double mu = 0.1 * r.du(), mv = 0.1 * r.dv();
  UvRect s{r.u0 - mu, r.u1 + mu, r.v0 - mv, r.v1 + mv};
  if (uPeriod_ == 0) s.u0 = std::max(s.u0, u0_), s.u1 = std::min(s.u1, u1_);
  if (vPeriod_ == 0) s.v0 = std::max(s.v0, v0_), s.v1 = std::min(s.v1, v1_);
  return s;
}

const SurfaceJet& FaceModel::nearestSeed(const SurfacePatch& patch, const gp_Pnt& x) const noexcept {
  const SurfaceJet* nearest = &patch.seeds[0];
  double best = INFINITY;
  for (const SurfaceJet& s : patch.seeds)
    if (const double d = s.p.SquareDistance(x); d < best) best = d, nearest = &s;
  return *nearest;
}

FaceSearch FaceModel::projectPatch(const gp_Pnt& x, int index, FaceStart start, double bound, FaceFoot& foot,
                                   const FaceFoot* best) const noexcept {
  const SurfacePatch& patch = patches_[index];
  const UvRect rect = searchRect(patch);
  const Vec3 xv(x.X(), x.Y(), x.Z());
  // Brings t next to the rectangle across a seam.
  auto near = [](double t, double lo, double period) { return period > 0 ? wrap(t, lo, period) : t; };
  auto inRect = [&rect](double u, double v) { return u >= rect.u0 && u <= rect.u1 && v >= rect.v0 && v <= rect.v1; };
  FaceSearch search;
  if (best) {
    // The best foot so far is on this face. In the patch's rectangle it is the patch's
    // one minimum closer than the bound (when that is certain): nothing to search.
    // Beside it, the search starts from its nearest point of the rectangle, from which
    // it is pushed out at once unless the patch holds a foot of its own.
    const double bu = near(best->u, rect.u0, uPeriod_), bv = near(best->v, rect.v0, vPeriod_);
    if (inRect(bu, bv) && (patch.focalClear(xv) || patch.minimumIsGlobal(xv, bound + std::abs(offset_)))) {
      search.u = best->u;
      search.v = best->v;
      return search;
    }
    start = {true, std::clamp(bu, rect.u0, rect.u1), std::clamp(bv, rect.v0, rect.v1), nullptr};
  }
  SurfaceJet from;
  bool evaluated = false;
  if (start.warm) {
    from.u = near(start.u, rect.u0, uPeriod_);
    from.v = near(start.v, rect.v0, vPeriod_);
  }
  if (start.warm && inRect(from.u, from.v)) {
    if (start.jet && start.jet->u == start.u && start.jet->v == start.v) {
      from = *start.jet;  // evaluated last tick, at the same parameters
      from.u = near(from.u, rect.u0, uPeriod_);
      from.v = near(from.v, rect.v0, vPeriod_);
      evaluated = true;
    }
  } else {
    from = nearestSeed(patch, x);  // its first step costs no evaluation either
    evaluated = true;
  }
  // After a Newton step shorter than this the next would be below the precision: the
  // error shrinks like step^2 over the length on which the surface bends.
  const double bendLength = std::min(patch.spread, 1 / std::max({patch.kTowards, patch.kAway, 1e-300}));
  const NewtonResult n =
      newtonInRect(Basis{this}, x, rect, from, evaluated, precision_, std::sqrt(precision_ * bendLength));
  search.u = n.u;
  search.v = n.v;
  if (n.end == SearchEnd::Interior) {
    // The foot from the last evaluation, to second order: no evaluation more.
    gp_Vec normal = n.jet.normalAt(n.u - n.jet.u, n.v - n.jet.v);
    if (normal.Magnitude() > 0) normal.Normalize();
    const gp_Pnt point = n.jet.pointAt(n.u - n.jet.u, n.v - n.jet.v).Translated(normal * offset_);
    search.found = accept(x, n.u, n.v, bound, foot, &point);
    if (search.found) {
      foot.normal = reversed_ ? normal.Reversed() : normal;
      foot.jet = n.jet;
      foot.hasJet = true;
      search.u = foot.u;
      search.v = foot.v;
    }
  }
  // Certain when Newton's minimum is the patch's closest point, or when being pushed out
  // of the patch proves it holds none closer than the bound. (The basis of an offset
  // surface stands |d| farther or nearer than the surface itself.)
  const double d = std::abs(offset_);
  if (n.end == SearchEnd::Interior) {
    const gp_Pnt basisPoint = n.jet.pointAt(n.u - n.jet.u, n.v - n.jet.v);
    search.certain = patch.focalClear(xv) || patch.minimumIsGlobal(xv, basisPoint.Distance(x));
  } else {
    search.certain = n.end != SearchEnd::Failed && (patch.focalClear(xv) || patch.clearOfFocus(xv, bound + d));
  }
  return search;
}

FaceSearch FaceModel::project(const gp_Pnt& x, int patch, const FaceStart& start, double bound, FaceFoot& foot,
                              const FaceFoot* best) const noexcept {
  if (patch < 0) return projectClosedForm(x, bound, foot);
  return projectPatch(x, patch, start, bound, foot, best);
}

FaceSearch FaceModel::exhaust(const gp_Pnt& x, int index, double bound, FaceFoot& foot, int& budget) const noexcept {
  const SurfacePatch& patch = patches_[index];
  FaceFoot candidate;
  const BranchResult r = branchAndBound(
      *this, x, patch, bound,
      [&](double u, double v) { return accept(x, u, v, INFINITY, candidate); },
      [&](const UvRect& cell) { return domain_.rectOutside(cell.u0, cell.u1, cell.v0, cell.v1); }, accuracy_,
      precision_, budget);
  FaceSearch search;
  search.certain = r.certain;
  if (r.found && accept(x, r.u, r.v, bound, foot)) search.found = true;
  return search;
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

std::size_t FaceModel::memoryBytes() const noexcept {
  return sizeof(*this) + patches_.capacity() * sizeof(SurfacePatch) + domain_.memoryBytes() +
         evaluator_.memoryBytes();
}

}  // namespace hg::geometry::exact
