#pragma once
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

namespace hg::geometry::exact {

// The surface at one (u, v): its point and first and second derivatives. Near it the
// surface is known to second order without evaluating it again.
struct SurfaceJet {
  double u = 0, v = 0;
  gp_Pnt p;
  gp_Vec du, dv, duu, dvv, duv;
  // S(u + a, v + b), to second order.
  gp_Pnt pointAt(double a, double b) const noexcept {
    return p.Translated(du * a + dv * b + (duu * (a * a) + duv * (2 * a * b) + dvv * (b * b)) * 0.5);
  }
  // S_u x S_v at (u + a, v + b), to first order.
  gp_Vec normalAt(double a, double b) const noexcept {
    return (du + duu * a + duv * b).Crossed(dv + duv * a + dvv * b);
  }
};

}  // namespace hg::geometry::exact
