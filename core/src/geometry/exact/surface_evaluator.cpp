#include "surface_evaluator.hpp"

#include <Geom_BSplineSurface.hxx>

#include <algorithm>
#include <cmath>

namespace hg::geometry::exact {
namespace {

// The span of `knots` holding t (clamped to the first and last span).
int spanOf(const std::vector<double>& knots, double t) {
  const auto it = std::upper_bound(knots.begin(), knots.end(), t);
  return std::clamp(static_cast<int>(it - knots.begin()) - 1, 0, static_cast<int>(knots.size()) - 2);
}

}  // namespace

SurfaceEvaluator::SurfaceEvaluator(const Handle(Geom_Surface)& surface) : surface_(surface) {
  const Handle(Geom_BSplineSurface) bs = Handle(Geom_BSplineSurface)::DownCast(surface);
  if (bs.IsNull()) return;
  for (int i = 1; i <= bs->NbUKnots(); ++i) uKnots_.push_back(bs->UKnot(i));
  for (int i = 1; i <= bs->NbVKnots(); ++i) vKnots_.push_back(bs->VKnot(i));
  uPeriodic_ = bs->IsUPeriodic();
  vPeriodic_ = bs->IsVPeriodic();
  const int nu = static_cast<int>(uKnots_.size()) - 1, nv = static_cast<int>(vKnots_.size()) - 1;
  const TColStd_Array2OfReal* weights = bs->Weights();
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 0.5 * (uKnots_[i] + uKnots_[i + 1]), v = 0.5 * (vKnots_[j] + vKnots_[j + 1]);
      Handle(BSplSLib_Cache) cache = new BSplSLib_Cache(bs->UDegree(), bs->IsUPeriodic(), bs->UKnotSequence(),
                                                        bs->VDegree(), bs->IsVPeriodic(), bs->VKnotSequence(), weights);
      cache->BuildCache(u, v, bs->UKnotSequence(), bs->VKnotSequence(), bs->Poles(), weights);
      spans_.push_back(cache);
    }
  cacheBytes_ = spans_.size() * (bs->UDegree() + 1) * (bs->VDegree() + 1) * 4 * sizeof(double);
}

const BSplSLib_Cache* SurfaceEvaluator::cacheAt(double& u, double& v) const noexcept {
  if (spans_.empty()) return nullptr;
  auto intoPeriod = [](double& t, const std::vector<double>& knots) {
    const double lo = knots.front(), period = knots.back() - lo;
    t -= std::floor((t - lo) / period) * period;
  };
  if (uPeriodic_) intoPeriod(u, uKnots_);
  if (vPeriodic_) intoPeriod(v, vKnots_);
  const int nv = static_cast<int>(vKnots_.size()) - 1;
  return spans_[spanOf(uKnots_, u) * nv + spanOf(vKnots_, v)].get();
}

gp_Pnt SurfaceEvaluator::value(double u, double v) const noexcept {
  gp_Pnt p;
  if (const BSplSLib_Cache* c = cacheAt(u, v)) c->D0(u, v, p);
  else surface_->D0(u, v, p);
  return p;
}

void SurfaceEvaluator::d1(double u, double v, gp_Pnt& p, gp_Vec& du, gp_Vec& dv) const noexcept {
  if (const BSplSLib_Cache* c = cacheAt(u, v)) c->D1(u, v, p, du, dv);
  else surface_->D1(u, v, p, du, dv);
}

void SurfaceEvaluator::d2(double u, double v, gp_Pnt& p, gp_Vec& du, gp_Vec& dv, gp_Vec& duu, gp_Vec& dvv,
                          gp_Vec& duv) const noexcept {
  if (const BSplSLib_Cache* c = cacheAt(u, v)) c->D2(u, v, p, du, dv, duu, dvv, duv);
  else surface_->D2(u, v, p, du, dv, duu, dvv, duv);
}

std::size_t SurfaceEvaluator::memoryBytes() const noexcept {
  return sizeof(*this) + cacheBytes_ + (uKnots_.capacity() + vKnots_.capacity()) * sizeof(double);
}

}  // namespace hg::geometry::exact
