#pragma once
// One B-rep face, prepared once for closest-point queries. Elementary faces (plane,
// cylinder, sphere, cone, torus) list the local minima of the distance in closed form
// (closed_form_foot.hpp); every other surface (revolution, extrusion, offset, B-spline,
// Bézier, ...) is cut into nearly flat patches (surface_patches.hpp), each searched by
// Newton where x is clear of its focal points and exhaustively elsewhere
// (patch_search.hpp). Either way the
// answer is the face's closest interior point, or the proof that there is none closer
// than a bound (its boundary's edges and vertices answer for the rest).
#include <Geom_Surface.hxx>
#include <GeomAbs_SurfaceType.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Cone.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>
#include <gp_Torus.hxx>

#include <vector>

#include "closed_form_foot.hpp"
#include "surface_jet.hpp"
#include "surface_evaluator.hpp"
#include "surface_patches.hpp"
#include "uv_domain.hpp"

namespace hg::geometry::exact {

// Where a point projects on a face: the foot and its parameters; on a freeform face also
// its outward normal and the surface's last evaluation (the next tick's free first step).
struct FaceFoot {
  double u = 0, v = 0;
  gp_Pnt point;
  double distance = 0;
  bool hasJet = false;
  gp_Vec normal;   // outward, unit (with the jet)
  SurfaceJet jet;
};

// Where a search on a face starts: cold, at (u, v), or at a jet already evaluated there.
struct FaceStart {
  bool warm = false;
  double u = 0, v = 0;
  const SurfaceJet* jet = nullptr;
};

// What a search on a face or patch established.
struct FaceSearch {
  bool found = false;    // a foot closer than the bound, inside the trimmed face
  bool certain = true;   // false: a closer foot may hide on the patch (x near its focal points)
  double u = 0, v = 0;   // where the search ended: the next tick's warm start
};

class FaceModel {
 public:
  FaceModel(const TopoDS_Face& face, double characteristicLength);

  // Freeform faces are searched patch by patch (each a leaf of the part's BVH); the
  // others as a whole (patch -1).
  const std::vector<SurfacePatch>& patches() const { return patches_; }
  bool freeform() const { return !patches_.empty(); }

  // The closest point of the face (or of one patch of it) to x, if closer than `bound`.
  // `best`: the best foot so far when it lies on this face, or null.
  FaceSearch project(const gp_Pnt& x, int patch, const FaceStart& start, double bound, FaceFoot& foot,
                     const FaceFoot* best = nullptr) const noexcept;
  // The exhaustive search of one patch (the fallback where `project` was not certain).
  // `budget`: the surface or curve evaluations it may still spend, less what it spent.
  FaceSearch exhaust(const gp_Pnt& x, int patch, double bound, FaceFoot& foot, int& budget) const noexcept;
  // Whether a Newton search on the face (or patch) is certain for x when only feet closer
  // than `best` matter: always on the elementary faces, where x is clear of the patch's
  // focal points on the others.
  bool certainFor(int patch, const Vec3& x, double best) const noexcept {
    return patch < 0 || patches_[patch].focalClear(x) || patches_[patch].clearOfFocus(x, best + std::abs(offset_));
  }

  bool contains(double u, double v) const noexcept { return domain_.contains(u, v); }
  // Outward unit normal at (u, v).
  gp_Vec normalAt(double u, double v) const noexcept;
  std::size_t memoryBytes() const noexcept;

  // The face's surface at (u, v) of its parameter box, wrapped across a closed direction.
  gp_Pnt value(double u, double v) const noexcept;
  void d2(double u, double v, gp_Pnt& p, gp_Vec& du, gp_Vec& dv, gp_Vec& duu, gp_Vec& dvv, gp_Vec& duv) const noexcept;

  // What Newton searches: the surface itself, or for a face on an offset surface its
  // basis. S + d N and S have the same critical points of the distance (x - S is along
  // N at both), and the basis is evaluated from its span caches: an offset surface's own
  // second derivatives need the basis's third, uncached.
  struct Basis {
    const FaceModel* face;
    gp_Pnt value(double u, double v) const noexcept { return face->evaluator_.value(face->wrapU(u), face->wrapV(v)); }
    void d2(double u, double v, gp_Pnt& p, gp_Vec& du, gp_Vec& dv, gp_Vec& duu, gp_Vec& dvv,
            gp_Vec& duv) const noexcept {
      face->evaluator_.d2(face->wrapU(u), face->wrapV(v), p, du, dv, duu, dvv, duv);
    }
  };

 private:
  SurfaceFeet closedFormFeet(const gp_Pnt& x) const noexcept;
  FaceSearch projectClosedForm(const gp_Pnt& x, double bound, FaceFoot& foot) const noexcept;
  FaceSearch projectPatch(const gp_Pnt& x, int patch, FaceStart start, double bound, FaceFoot& foot,
                          const FaceFoot* best) const noexcept;
  // Where Newton starts on a patch when nothing warm lies in its rectangle: the seed
  // nearest to x.
  const SurfaceJet& nearestSeed(const SurfacePatch& patch, const gp_Pnt& x) const noexcept;
  // A point of the surface accepted as the face's foot: in the face's box (after wrapping)
  // and in the trimmed face, and closer than the bound. `point`: S(u, v), when known.
  bool accept(const gp_Pnt& x, double u, double v, double bound, FaceFoot& foot,
              const gp_Pnt* point = nullptr) const noexcept;
  bool wrapOrClamp(double& u, double& v) const noexcept;  // false if clamped
  UvRect searchRect(const SurfacePatch& patch) const noexcept;
  // A closed direction that the surface does not know as periodic (a loft through closed
  // sections) is wrapped by hand before evaluation.
  static double wrapClosed(double t, double lo, double period, bool periodic) noexcept;
  double wrapU(double u) const noexcept { return wrapClosed(u, u0_, uPeriod_, uPeriodic_); }
  double wrapV(double v) const noexcept { return wrapClosed(v, v0_, vPeriod_, vPeriodic_); }
  void buildPatches();
  void growForOffset(SurfacePatch& patch) const;

  Handle(Geom_Surface) surface_;     // the face's surface, rectangular trims removed
  double offset_;                    // surface_ = basis_ + offset_ N (0: no offset)
  Handle(Geom_Surface) basis_;       // what evaluator_ evaluates: surface_, or its offset basis
  SurfaceEvaluator evaluator_;
  GeomAbs_SurfaceType type_;
  gp_Pln plane_;
  gp_Cylinder cylinder_;
  gp_Sphere sphere_;
  gp_Cone cone_;
  gp_Torus torus_;
  double u0_, u1_, v0_, v1_;          // the face's UV box
  double uPeriod_ = 0, vPeriod_ = 0;  // > 0 when the face spans a closed direction: wrap
  bool uPeriodic_ = false, vPeriodic_ = false;  // the surface itself is periodic there
  bool reversed_;
  double tolerance_;                  // model units
  double precision_;                  // model units: how close Newton takes the foot
  double accuracy_;                   // model units: what the exhaustive search settles to
  UvDomain domain_;
  std::vector<SurfacePatch> patches_;  // freeform only
};

}  // namespace hg::geometry::exact
