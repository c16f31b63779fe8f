#include "edge_model.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRep_Tool.hxx>
#include <ElCLib.hxx>

#include <algorithm>
#include <cmath>

namespace hg::geometry::exact {

EdgeModel::EdgeModel(const TopoDS_Edge& edge, const std::vector<std::pair<TopoDS_Face, int>>& faces) {
  if (BRep_Tool::Degenerated(edge)) return;
  for (const auto& [face, index] : faces)
    if (BRep_Tool::IsClosed(edge, face)) return;  // a seam: its face covers it
  curve_ = BRep_Tool::Curve(edge, t0_, t1_);
  if (curve_.IsNull() || faces.empty()) return;
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
    const int n = 32;
    for (int i = 0; i <= n; ++i) {
      const double t = t0_ + (t1_ - t0_) * i / n;
      seeds_.emplace_back(t, curve_->Value(t));
    }
  }
  usable_ = true;
}

// Brings t into the edge's range: wraps a whole periodic edge, otherwise leaves it be.
double EdgeModel::fit(double t) const noexcept {
  if (period_ > 0) t = t0_ + std::fmod(std::fmod(t - t0_, period_) + period_, period_);
  return t;
}

// Minimises |C(t) - x|^2 by Newton (Gauss-Newton where the curvature term would make it
// climb). Convergence is judged on the step actually taken: at a clamped end the proposed
// step never shrinks, and the end belongs to a vertex anyway.
bool EdgeModel::newton(const gp_Pnt& x, double& t) const noexcept {
  gp_Pnt c;
  gp_Vec d1, d2;
  int clamped = 0;
  for (int iteration = 0; iteration < 30; ++iteration) {
    curve_->D2(t, c, d1, d2);
    const gp_Vec r(x, c);
    const double g = r.Dot(d1), h = d1.Dot(d1) + r.Dot(d2);
    double dt = -g / (h > 0 ? h : d1.Dot(d1));
    if (!std::isfinite(dt)) return false;
    dt = std::clamp(dt, -0.25 * (t1_ - t0_), 0.25 * (t1_ - t0_));
    const double next = std::clamp(fit(t + dt), t0_, t1_);
    if (period_ == 0 && next != fit(t + dt) && ++clamped == 2) return false;
    const double moved = std::abs(next - t);
    t = next;
    // Quadratic convergence: once a step moves the point by less than this, the next
    // would be below rounding (a stricter test only burns iterations).
    if (moved * std::sqrt(d1.SquareMagnitude()) < 1e-12 * (1 + c.XYZ().Modulus())) break;
  }
  return true;
}

bool EdgeModel::project(const gp_Pnt& x, bool warm, double& t, double bound, EdgeFoot& foot) const noexcept {
  if (type_ == GeomAbs_Line) {
    t = ElCLib::Parameter(line_, x);
  } else if (type_ == GeomAbs_Circle) {
    // ElCLib answers in [0, 2pi); an arc's range may start anywhere (and cross 2pi).
    const double twoPi = 2 * M_PI;
    t = t0_ + std::fmod(std::fmod(ElCLib::Parameter(circle_, x) - t0_, twoPi) + twoPi, twoPi);
  } else {
    if (!warm) {
      double best = INFINITY;
      for (const auto& [ts, p] : seeds_)
        if (const double d = p.SquareDistance(x); d < best) best = d, t = ts;
    }
    if (!newton(x, t)) return false;
  }
  // The ends belong to the vertices (a whole periodic edge has none).
  const double margin = 1e-12 * std::max(1.0, t1_ - t0_);
  if (period_ == 0 && (t <= t0_ + margin || t >= t1_ - margin)) return false;
  if (t < t0_ || t > t1_) return false;
  const gp_Pnt p = curve_->Value(t);
  const double d = p.Distance(x);
  if (d >= bound) return false;
  foot = {t, p, d};
  return true;
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
