#pragma once
// One B-rep face, prepared once for fast closest-point queries: its untrimmed surface
// (with closed forms for the elementary kinds), its UV box, how it wraps, a trimmed-face
// classifier and, for freeform surfaces, seeds for the cold global search.
#include <Geom_Surface.hxx>
#include <GeomAbs_SurfaceType.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Cone.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>
#include <gp_Torus.hxx>

#include <vector>

#include "surface_evaluator.hpp"
#include "uv_domain.hpp"

namespace hg::geometry::exact {

struct SurfaceSeed {
  double u, v;
  gp_Pnt point;
};

// Where a point projects on a face: the foot, its parameters and the outward normal.
struct FaceFoot {
  double u = 0, v = 0;
  gp_Pnt point;
  gp_Vec normal;       // outward (face orientation applied), unit
  double distance = 0;
};

class FaceModel {
 public:
  FaceModel(const TopoDS_Face& face, double characteristicLength);

  // The closest point of the face to x, from (u, v) when `warm`, else from the closed form
  // or the nearest seed; (u, v) is left where the search ended, for the next warm start.
  // False when the surface's closest point lies outside the trimmed face (an edge or
  // vertex of the face is then closer) or when `bound` cannot be beaten.
  bool project(const gp_Pnt& x, bool warm, double& u, double& v, double bound, FaceFoot& foot) const noexcept;
  // Whether (u, v) lies inside the trimmed face.
  bool contains(double u, double v) const noexcept { return insideTrimmedFace(u, v); }
  // Outward unit normal at (u, v).
  gp_Vec normalAt(double u, double v) const noexcept;
  std::size_t memoryBytes() const noexcept;

 private:
  bool closedForm(const gp_Pnt& x, double& u, double& v) const noexcept;
  void nearestSeed(const gp_Pnt& x, double& u, double& v) const noexcept;
  bool newton(const gp_Pnt& x, double& u, double& v) const noexcept;
  bool wrapOrClamp(double& u, double& v) const noexcept;  // false if clamped
  bool insideTrimmedFace(double u, double v) const noexcept;
  void buildSeeds(const TopoDS_Face& face);

  Handle(Geom_Surface) surface_;
  SurfaceEvaluator evaluator_;
  GeomAbs_SurfaceType type_;
  gp_Pln plane_;
  gp_Cylinder cylinder_;
  gp_Sphere sphere_;
  gp_Cone cone_;
  gp_Torus torus_;
  double u0_, u1_, v0_, v1_;          // the face's UV box
  double uPeriod_ = 0, vPeriod_ = 0;  // > 0 when the face spans a closed direction: wrap
  bool reversed_;
  double tolerance_;                  // model units
  UvDomain domain_;
  std::vector<SurfaceSeed> seeds_;    // freeform only
};

}  // namespace hg::geometry::exact
