#include "primitive_recognition.hpp"

#include <BRepAdaptor_Surface.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>

#include <cmath>
#include <numbers>
#include <vector>

namespace hg::geometry {
namespace {

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

bool sameVolume(double a, double b) { return std::abs(a - b) <= 1e-6 * std::abs(b); }

struct Faces {
  std::vector<gp_Pln> planes;
  std::vector<gp_Cylinder> cylinders;
  std::vector<gp_Sphere> spheres;
  int other = 0;
};

Faces classifyFaces(const TopoDS_Shape& solid) {
  Faces faces;
  for (TopExp_Explorer ex(solid, TopAbs_FACE); ex.More(); ex.Next()) {
    BRepAdaptor_Surface s(TopoDS::Face(ex.Current()), false);
    switch (s.GetType()) {
      case GeomAbs_Plane: faces.planes.push_back(s.Plane()); break;
      case GeomAbs_Cylinder: faces.cylinders.push_back(s.Cylinder()); break;
      case GeomAbs_Sphere: faces.spheres.push_back(s.Sphere()); break;
      default: ++faces.other;
    }
  }
  return faces;
}

// Two caps perpendicular to the axis: the cylinder spans between them.
Primitive cylinder(const gp_Cylinder& c, const gp_Pln& a, const gp_Pln& b, double s, double volume) {
  const gp_Dir axis = c.Axis().Direction();
  if (!a.Axis().Direction().IsParallel(axis, 1e-9) || !b.Axis().Direction().IsParallel(axis, 1e-9))
    return {};
  const gp_XYZ o = c.Location().XYZ();
  const double ta = (a.Location().XYZ() - o).Dot(axis.XYZ());
  const double tb = (b.Location().XYZ() - o).Dot(axis.XYZ());
  const double r = c.Radius() * s, h = std::abs(tb - ta) * s;
  if (!sameVolume(std::numbers::pi * r * r * h, volume)) return {};
  Primitive p;
  p.kind = Primitive::Kind::Cylinder;
  p.radius = r;
  p.halfLength = h / 2;
  p.centre = toVec(o + axis.XYZ() * (0.5 * (ta + tb))) * s;
  const gp_Ax3& ax = c.Position();
  p.axes.col(0) = toVec(ax.XDirection().XYZ());
  p.axes.col(1) = toVec(ax.YDirection().XYZ());
  p.axes.col(2) = toVec(axis.XYZ());
  if (p.axes.determinant() < 0) p.axes.col(1) = -p.axes.col(1);
  return p;
}

// Six planes in three parallel pairs, mutually perpendicular, enclosing the B-rep volume.
Primitive box(const std::vector<gp_Pln>& planes, double s, double volume) {
  Primitive p;
  Vec3 lo, hi;
  std::vector<bool> used(6, false);
  int axis = 0;
  for (int i = 0; i < 6 && axis < 3; ++i) {
    if (used[i]) continue;
    const gp_Dir d = planes[i].Axis().Direction();
    for (int j = i + 1; j < 6; ++j) {
      if (used[j] || !planes[j].Axis().Direction().IsParallel(d, 1e-9)) continue;
      used[i] = used[j] = true;
      const double ti = planes[i].Location().XYZ().Dot(d.XYZ());
      const double tj = planes[j].Location().XYZ().Dot(d.XYZ());
      p.axes.col(axis) = toVec(d.XYZ());
      lo[axis] = std::min(ti, tj) * s;
      hi[axis] = std::max(ti, tj) * s;
      ++axis;
      break;
    }
  }
  if (axis != 3) return {};
  if (std::abs(p.axes.col(0).dot(p.axes.col(1))) > 1e-9 || std::abs(p.axes.col(0).dot(p.axes.col(2))) > 1e-9 ||
      std::abs(p.axes.col(1).dot(p.axes.col(2))) > 1e-9)
    return {};
  if (p.axes.determinant() < 0) {
    p.axes.col(2) = -p.axes.col(2);
    std::swap(lo[2], hi[2]);
    lo[2] = -lo[2];
    hi[2] = -hi[2];
  }
  const Vec3 size = hi - lo;
  if (!sameVolume(size.prod(), volume)) return {};
  p.kind = Primitive::Kind::Box;
  p.halfExtents = size / 2;
  p.centre = p.axes * (0.5 * (lo + hi));
  return p;
}

}  // namespace

const char* toString(Primitive::Kind kind) {
  switch (kind) {
    case Primitive::Kind::Cylinder: return "cylinder";
    case Primitive::Kind::Box: return "box";
    case Primitive::Kind::Sphere: return "sphere";
    default: return "none";
  }
}

Primitive recognisePrimitive(const TopoDS_Shape& solid, double s, double volume) {
  const Faces f = classifyFaces(solid);
  if (f.other != 0) return {};
  if (f.cylinders.size() == 1 && f.planes.size() == 2 && f.spheres.empty())
    return cylinder(f.cylinders[0], f.planes[0], f.planes[1], s, volume);
  if (f.planes.size() == 6 && f.cylinders.empty() && f.spheres.empty()) return box(f.planes, s, volume);
  if (f.spheres.size() == 1 && f.planes.empty() && f.cylinders.empty()) {
    const double r = f.spheres[0].Radius() * s;
    if (!sameVolume(4.0 / 3.0 * std::numbers::pi * r * r * r, volume)) return {};
    Primitive p;
    p.kind = Primitive::Kind::Sphere;
    p.radius = r;
    p.centre = toVec(f.spheres[0].Location().XYZ()) * s;
    return p;
  }
  return {};
}

}  // namespace hg::geometry
