#pragma once
// The points of an elementary surface (plane, cylinder, cone, sphere, torus) that can be
// the closest point of a face on it to x: the local minima of the distance, in closed
// form. A surface of revolution holds its foot in the meridian plane through x, either on
// x's side of the axis or on the far side; on a cone (both nappes) or a torus whose minor
// radius exceeds the major (apple and lemon tori) both can be local minima, so a face that
// holds only the farther one still has its foot there. Listing every local minimum is
// what lets a trimmed face be answered exactly: its closest point is one of them, or lies
// on its boundary (an edge or a vertex answers then).
#include <gp_Cone.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Pnt.hxx>
#include <gp_Sphere.hxx>
#include <gp_Torus.hxx>

namespace hg::geometry::exact {

struct SurfaceFeet {
  static constexpr int kMax = 2;
  int count = 0;
  double u[kMax] = {0, 0}, v[kMax] = {0, 0};
  // x lies on the axis (or at a sphere's centre): every u (every u and v) is as close;
  // the caller picks one inside its face.
  bool anyU = false, anyV = false;
  void add(double uu, double vv) {
    if (count < kMax) u[count] = uu, v[count] = vv, ++count;
  }
};

SurfaceFeet planeFeet(const gp_Pln& plane, const gp_Pnt& x) noexcept;
SurfaceFeet cylinderFeet(const gp_Cylinder& cylinder, const gp_Pnt& x) noexcept;
SurfaceFeet sphereFeet(const gp_Sphere& sphere, const gp_Pnt& x) noexcept;
SurfaceFeet coneFeet(const gp_Cone& cone, const gp_Pnt& x) noexcept;
SurfaceFeet torusFeet(const gp_Torus& torus, const gp_Pnt& x) noexcept;

}  // namespace hg::geometry::exact
