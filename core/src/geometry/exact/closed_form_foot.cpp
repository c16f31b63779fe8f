#include "closed_form_foot.hpp"

#include <ElSLib.hxx>

#include <cmath>

namespace hg::geometry::exact {
namespace {

// x in the surface's own frame: the angle about the axis, the distance from it (s >= 0)
// and the height along it.
struct Meridian {
  double u, s, z;
  bool onAxis;
};

Meridian meridianOf(const gp_Ax3& frame, const gp_Pnt& x) noexcept {
  const gp_Vec d(frame.Location(), x);
  const double a = d.Dot(frame.XDirection()), b = d.Dot(frame.YDirection()), z = d.Dot(frame.Direction());
  const double s = std::hypot(a, b);
  // On the axis to rounding of the point's own coordinates: every meridian is as close.
  const bool onAxis = s <= 1e-14 * (std::abs(z) + d.Magnitude()) || s == 0;
  return {onAxis ? 0.0 : std::atan2(b, a), s, z, onAxis};
}

}  // namespace

SurfaceFeet planeFeet(const gp_Pln& plane, const gp_Pnt& x) noexcept {
  SurfaceFeet f;
  double u, v;
  ElSLib::Parameters(plane, x, u, v);
  f.add(u, v);
  return f;
}

SurfaceFeet cylinderFeet(const gp_Cylinder& cylinder, const gp_Pnt& x) noexcept {
  SurfaceFeet f;
  const Meridian m = meridianOf(cylinder.Position(), x);
  f.add(m.u, m.z);
  f.anyU = m.onAxis;
  return f;
}

SurfaceFeet sphereFeet(const gp_Sphere& sphere, const gp_Pnt& x) noexcept {
  SurfaceFeet f;
  const Meridian m = meridianOf(sphere.Position(), x);
  if (m.onAxis && m.z == 0) {  // the centre: every point is as close
    f.add(0, 0);
    f.anyU = f.anyV = true;
    return f;
  }
  f.add(m.u, std::atan2(m.z, m.s));
  f.anyU = m.onAxis;
  return f;
}

// OCCT's cone: P(u, v) = O + (R + v sin a)(cos u X + sin u Y) + v cos a Z. In the meridian
// plane of x (coordinates s, z) it is two lines through the apex: (R + v sin a, v cos a)
// at u_x and (-(R + v sin a), v cos a) at u_x + pi. The foot on each line is a local
// minimum of the surface's distance when it lies on x's side of the axis (s > 0); the
// apex itself is a vertex of the B-rep.
SurfaceFeet coneFeet(const gp_Cone& cone, const gp_Pnt& x) noexcept {
  SurfaceFeet f;
  const Meridian m = meridianOf(cone.Position(), x);
  const double R = cone.RefRadius(), sa = std::sin(cone.SemiAngle()), ca = std::cos(cone.SemiAngle());
  const double v1 = (m.s - R) * sa + m.z * ca;
  if (R + v1 * sa > 0 || m.onAxis) f.add(m.u, v1);
  const double v2 = -(m.s + R) * sa + m.z * ca;
  if (-(R + v2 * sa) > 0 && !m.onAxis) f.add(m.u + M_PI, v2);
  f.anyU = m.onAxis;
  return f;
}

// OCCT's torus: P(u, v) = O + (R + r cos v)(cos u X + sin u Y) + r sin v Z. In the
// meridian plane of x it is two circles of radius r centred at s = +R and s = -R; the
// second reaches x's side of the axis only when r > R.
SurfaceFeet torusFeet(const gp_Torus& torus, const gp_Pnt& x) noexcept {
  SurfaceFeet f;
  const Meridian m = meridianOf(torus.Position(), x);
  const double R = torus.MajorRadius(), r = torus.MinorRadius();
  // Circle 1, centre (R, 0): foot along the direction from its centre to x.
  const double d1s = m.s - R, d1z = m.z, n1 = std::hypot(d1s, d1z);
  if (n1 == 0) {  // on the circle of tube centres: the whole meridian circle is as close
    f.add(m.u, 0);
    f.anyV = true;
  } else if (R + r * d1s / n1 > 0 || m.onAxis) {
    f.add(m.u, std::atan2(d1z, d1s));
  }
  if (!m.onAxis) {
    // Circle 2, centre (-R, 0), as the torus at u_x + pi draws it: (-(R + r cos v), r sin v).
    const double d2s = m.s + R, d2z = m.z, n2 = std::hypot(d2s, d2z);
    if (n2 > 0 && -R + r * d2s / n2 > 0) f.add(m.u + M_PI, std::atan2(d2z / n2, -d2s / n2));
  }
  f.anyU = m.onAxis;
  return f;
}

}  // namespace hg::geometry::exact
