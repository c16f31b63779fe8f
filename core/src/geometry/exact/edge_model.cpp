#include "edge_model.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRep_Tool.hxx>
#include <ElCLib.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_OffsetCurve.hxx>
#include <Geom_TrimmedCurve.hxx>

#include <algorithm>
#include <cmath>

#include "curve_search.hpp"

namespace hg::geometry::exact {
namespace {

// Where the curve's derivatives may jump: pieces never straddle these.
std::vector<double> knotBreaks(Handle(Geom_Curve) c) {
  for (;;) {
    if (auto t = Handle(Geom_TrimmedCurve)::DownCast(c); !t.IsNull()) c = t->BasisCurve();
    else if (auto o = Handle(Geom_OffsetCurve)::DownCast(c); !o.IsNull()) c = o->BasisCurve();
    else break;
  }
  std::vector<double> k;
  if (auto bs = Handle(Geom_BSplineCurve)::DownCast(c); !bs.IsNull())
    for (int i = 1; i <= bs->NbKnots(); ++i) k.push_back(bs->Knot(i));
  return k;
}

}  // namespace

EdgeModel::EdgeModel(const TopoDS_Edge& edge, const std::vector<std::pair<TopoDS_Face, int>>& faces,
                     double characteristicLength) {
  if (BRep_Tool::Degenerated(edge)) return;
  for (const auto& [face, index] : faces)
    if (BRep_Tool::IsClosed(edge, face)) return;  // a seam: its face covers it
  curve_ = BRep_Tool::Curve(edge, t0_, t1_);
  if (curve_.IsNull() || faces.empty() || !(t1_ > t0_)) return;
  tolerance_ = std::max(BRep_Tool::Tolerance(edge), 1e-12 * characteristicLength);
  accuracy_ = 1e-9 * characteristicLength;
  BRepAdaptor_Curve adaptor(edge);
  type_ = adaptor.GetType();
  if (type_ == GeomAbs_Line) line_ = adaptor.Line();
  if (type_ == GeomAbs_Circle) circle_ = adaptor.Circle();
  // A whole closed edge (a circle, a loft's rim) wraps at its seam vertex: a B-spline
  // through closed sections is closed without being periodic.
  if (curve_->IsPeriodic() && t1_ - t0_ >= curve_->Period() - 1e-12) period_ = curve_->Period();
  else if (BRep_Tool::IsClosed(edge)) period_ = t1_ - t0_;
  for (const auto& [face, index] : faces) {
    if (sideCount_ == 2) break;
    double f, l;
    Side& side = sides_[sideCount_++];
    side.face = index;
    side.pcurve = BRep_Tool::CurveOnSurface(edge, face, f, l);
  }
  if (type_ != GeomAbs_Line && type_ != GeomAbs_Circle) {
    PieceOptions options;
    options.tolerance = tolerance_;
    pieces_ = buildCurvePieces([this](double t, gp_Pnt& p, gp_Vec& d1, gp_Vec& dd2) { d2(t, p, d1, dd2); }, t0_, t1_,
                               knotBreaks(curve_), options);
  }
  usable_ = true;
}

// Brings t into the edge's range: wraps a whole closed edge, otherwise leaves it be.
double EdgeModel::fit(double t) const noexcept {
  if (period_ > 0) t = t0_ + std::fmod(std::fmod(t - t0_, period_) + period_, period_);
  return t;
}

// An interior point of the edge closer than `bound`: the ends belong to the vertices (a
// whole periodic edge has none).
bool EdgeModel::accept(const gp_Pnt& x, double t, double bound, EdgeFoot& foot) const noexcept {
  t = fit(t);
  const double margin = 1e-12 * std::max(1.0, t1_ - t0_);
  if (period_ == 0 && (t <= t0_ + margin || t >= t1_ - margin)) return false;
  if (t < t0_ || t > t1_) return false;
  const gp_Pnt p = curve_->Value(t);
  const double d = p.Distance(x);
  if (d >= bound) return false;
  foot = {t, p, d};
  return true;
}

EdgeSearch EdgeModel::projectPiece(const gp_Pnt& x, int index, bool warm, double& t, double bound,
                                   EdgeFoot& foot) const noexcept {
  const CurvePiece& piece = pieces_[index];
  const double margin = 0.1 * (piece.t1 - piece.t0);
  const double a = period_ > 0 ? piece.t0 - margin : std::max(t0_, piece.t0 - margin);
  const double b = period_ > 0 ? piece.t1 + margin : std::min(t1_, piece.t1 + margin);
  if (warm && period_ > 0) t = a + std::fmod(std::fmod(t - a, period_) + period_, period_);
  if (!warm || t < a || t > b) {
    double best = INFINITY;
    for (int k = 0; k < CurvePiece::kSeeds; ++k)
      if (const double d = piece.seedP[k].SquareDistance(x); d < best) best = d, t = piece.seedT[k];
  }
  const auto curve = [this](double s, gp_Pnt& p, gp_Vec& d1, gp_Vec& dd2) { d2(s, p, d1, dd2); };
  const SearchEnd end = newtonOnInterval(curve, x, a, b, t, tolerance_);
  EdgeSearch search;
  if (end == SearchEnd::Interior) {
    search.found = accept(x, t, bound, foot);
    search.certain = piece.minimumIsGlobal(curve_->Value(fit(t)).Distance(x));
  } else {
    search.certain = end != SearchEnd::Failed && piece.clearOfFocus(bound);
  }
  t = fit(t);
  return search;
}

EdgeSearch EdgeModel::project(const gp_Pnt& x, int piece, bool warm, double& t, double bound,
                              EdgeFoot& foot) const noexcept {
  if (piece >= 0) return projectPiece(x, piece, warm, t, bound, foot);
  if (type_ == GeomAbs_Line) {
    t = ElCLib::Parameter(line_, x);
  } else {
    // ElCLib answers in [0, 2pi); an arc's range may start anywhere (and cross 2pi).
    const double twoPi = 2 * M_PI;
    t = t0_ + std::fmod(std::fmod(ElCLib::Parameter(circle_, x) - t0_, twoPi) + twoPi, twoPi);
  }
  // A line's or circle's distance has one minimum: the edge's foot or one of its ends.
  EdgeSearch search;
  search.found = accept(x, t, bound, foot);
  return search;
}

EdgeSearch EdgeModel::exhaust(const gp_Pnt& x, int index, double bound, EdgeFoot& foot, int& budget) const noexcept {
  const auto curve = [this](double s, gp_Pnt& p, gp_Vec& d1, gp_Vec& dd2) { d2(s, p, d1, dd2); };
  EdgeFoot candidate;
  const CurveBranchResult r = branchAndBound1D(
      curve, x, pieces_[index], bound, [&](double t) { return accept(x, t, INFINITY, candidate); }, accuracy_,
      tolerance_, budget);
  EdgeSearch search;
  search.certain = r.certain;
  search.found = r.found && accept(x, r.t, bound, foot);
  return search;
}

gp_Vec EdgeModel::pseudoNormal(double t, const std::vector<FaceModel>& faces) const noexcept {
  gp_Vec n(0, 0, 0);
  for (int i = 0; i < sideCount_; ++i) {
    const Side& side = sides_[i];
    if (side.pcurve.IsNull()) continue;
    const gp_Pnt2d uv = side.pcurve->Value(t);
    n += faces[side.face].normalAt(uv.X(), uv.Y());
  }
  return n;
}

}  // namespace hg::geometry::exact
