// The reference back end: OCCT's own answer, used as the truth in tests and benchmarks.
// BRepExtrema_DistShapeShape against the shells (against a solid it answers 0 for every
// point inside) and ray parity for the sign. Both keep what they precompute about the part
// (boxes of the faces) across queries, so that the ladder compares against OCCT at its
// best; that state is mutable, so queries are serialised with a mutex. Slow, and it
// allocates: never on the servo thread.
//
// BRepExtrema alone is not always the truth: on a face of a surface of linear extrusion of
// a periodic B-spline (a cam) it missed the foot and answered the rim 0.1 mm farther
// (measured against brute force). So every face whose box could beat its answer is also
// searched by OCCT's generic extremum (Extrema_GenExtPS) from a dense grid, each minimum
// it finds kept if it lies inside the face, and the closer answer wins (tori and freeform
// faces: OCCT answers planes, cylinders, cones and spheres in closed form).
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepTools.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <Bnd_Box.hxx>
#include <Extrema_GenExtPS.hxx>
#include <Extrema_POnSurf.hxx>
#include <IntCurvesFace_ShapeIntersector.hxx>
#include <gp_Lin.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRep_Builder.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>

#include <memory>
#include <mutex>
#include <vector>

#include "hapticgrasp/geometry/backends.hpp"

namespace hg::geometry {
namespace {

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

class ReferencePenetration final : public PenetrationModel {
 public:
  explicit ReferencePenetration(PartModelPtr part) : part_(std::move(part)), s_(part_->metresPerUnit()) {
    BRep_Builder builder;
    builder.MakeCompound(shells_);
    for (TopExp_Explorer ex(part_->shape(), TopAbs_SHELL); ex.More(); ex.Next()) builder.Add(shells_, ex.Current());
    for (TopExp_Explorer ex(part_->shape(), TopAbs_SOLID); ex.More(); ex.Next())
      solids_.push_back(std::make_unique<SolidRays>(ex.Current(), 1e-9 * part_->characteristicLength() / s_));
    distance_.LoadS2(shells_);
    distance_.SetFlag(Extrema_ExtFlag_MIN);
    // OCCT's closed-form extrema are right on planes, cylinders, cones and spheres; on a torus
    // whose minor radius exceeds the major (an apple torus) it missed feet by up to 4 mm
    // (brute force agreed with the exact back end): tori and freeform faces are re-checked.
    const TopTools_IndexedMapOfShape& faces = part_->faces();
    for (int i = 1; i <= faces.Extent(); ++i) {
      const TopoDS_Face& face = TopoDS::Face(faces(i));
      const GeomAbs_SurfaceType type = BRepAdaptor_Surface(face, false).GetType();
      const bool elementary =
          type == GeomAbs_Plane || type == GeomAbs_Cylinder || type == GeomAbs_Cone || type == GeomAbs_Sphere;
      faceSearches_.push_back(elementary ? nullptr : std::make_unique<FaceSearch>(face));
    }
  }

  std::string_view name() const noexcept override { return "reference"; }
  std::string setting() const override { return "BRepExtrema + ray parity"; }
  std::size_t memoryBytes() const noexcept override { return sizeof(*this); }
  bool realTimeSafe() const noexcept override { return false; }

  Penetration query(const Vec3& xm, QueryState&) const noexcept override {
    if (!xm.allFinite()) return {};
    try {
      const gp_Pnt x(xm.x() / s_, xm.y() / s_, xm.z() / s_);
      const std::lock_guard lock(mutex_);
      BRepExtrema_DistShapeShape& distance = distance_;
      distance.LoadS1(BRepBuilderAPI_MakeVertex(x).Vertex());
      if (!distance.Perform() || distance.NbSolution() == 0) return {};
      Penetration p;
      gp_Pnt foot = distance.PointOnShape2(1);
      double d = distance.Value();
      const int closerFace = crossCheckFaces(x, d, foot);
      p.inside = d > 0 && classify(x) == TopAbs_IN;
      p.depth = (p.inside ? d : -d) * s_;
      p.foot = toVec(foot.XYZ()) * s_;
      p.vector = toVec(gp_Vec(foot, x).XYZ()) * s_;
      if (d > 0) p.normal = (p.inside ? -p.vector : p.vector).normalized();
      const TopoDS_Shape support = distance.SupportOnShape2(1);
      if (closerFace > 0) {
        p.feature = Feature::Face;
        p.featureIndex = closerFace;
        return p;
      }
      switch (distance.SupportTypeShape2(1)) {
        case BRepExtrema_IsInFace:
          p.feature = Feature::Face;
          p.featureIndex = part_->faces().FindIndex(support);
          break;
        case BRepExtrema_IsOnEdge:
          p.feature = Feature::Edge;
          p.featureIndex = part_->edges().FindIndex(support);
          break;
        default:
          p.feature = Feature::Vertex;
          p.featureIndex = part_->vertices().FindIndex(support);
      }
      return p;
    } catch (const Standard_Failure&) {
      return {};
    }
  }

 private:
  // One face and OCCT's generic extremum on it, initialised once (its sample grid).
  struct FaceSearch {
    TopoDS_Face face;
    BRepAdaptor_Surface surface;
    Bnd_Box box;
    BRepTopAdaptor_FClass2d classifier;
    Extrema_GenExtPS extrema;
    explicit FaceSearch(const TopoDS_Face& f)
        : face(f), surface(f), classifier(f, Precision::PConfusion()) {
      BRepBndLib::AddOptimal(f, box, false, false);  // Add() missed part of an extrusion face
      double u0, u1, v0, v1;
      BRepTools::UVBounds(f, u0, u1, v0, v1);
      extrema.Initialize(surface, 48, 48, u0, u1, v0, v1, Precision::PConfusion(), Precision::PConfusion());
      extrema.SetFlag(Extrema_ExtFlag_MIN);
    }
  };

  // The closest foot inside a face that beats d, if any: d and foot become it and the
  // face's 1-based index is returned (0: BRepExtrema's answer stands).
  int crossCheckFaces(const gp_Pnt& x, double& d, gp_Pnt& foot) const {
    int closer = 0;
    for (std::size_t i = 0; i < faceSearches_.size(); ++i) {
      if (!faceSearches_[i]) continue;
      FaceSearch& f = *faceSearches_[i];
      if (f.box.Distance(Bnd_Box(x, x)) >= d) continue;
      f.extrema.Perform(x);
      if (!f.extrema.IsDone()) continue;
      for (int k = 1; k <= f.extrema.NbExt(); ++k) {
        const double dk = std::sqrt(f.extrema.SquareDistance(k));
        if (dk >= d - 1e-12 * part_->characteristicLength() / s_) continue;
        double u, v;
        f.extrema.Point(k).Parameter(u, v);
        if (f.classifier.Perform(gp_Pnt2d(u, v)) != TopAbs_IN) continue;
        d = dk;
        foot = f.extrema.Point(k).Value();
        closer = static_cast<int>(i) + 1;
      }
    }
    return closer;
  }

  // Whether x is inside a solid: the parity of the crossings of rays from x with its
  // faces, the majority of five rays in unrelated directions. (BRepClass3d_SolidClassifier,
  // and so FreeCAD's isInside(), called points in the 1.5 mm wall of a cup made by
  // makeThickness outside, where rays cross its faces an odd number of times.) A ray that
  // grazes an edge or a face may count wrong; the others outvote it.
  struct SolidRays {
    IntCurvesFace_ShapeIntersector intersector;
    explicit SolidRays(const TopoDS_Shape& solid, double tolerance) { intersector.Load(solid, tolerance); }
    bool contains(const gp_Pnt& x) {
      static const gp_Dir directions[] = {gp_Dir(0.5773, 0.3219, 0.7506), gp_Dir(-0.6917, 0.4373, 0.5747),
                                          gp_Dir(0.1201, -0.9312, 0.3442), gp_Dir(-0.3541, -0.2789, -0.8926),
                                          gp_Dir(0.8327, -0.4519, -0.3201)};
      int inside = 0;
      for (const gp_Dir& d : directions) {
        intersector.Perform(gp_Lin(x, d), 0, Precision::Infinite());
        inside += intersector.IsDone() && intersector.NbPnt() % 2 == 1;
      }
      return 2 * inside > static_cast<int>(std::size(directions));
    }
  };

  TopAbs_State classify(const gp_Pnt& x) const {
    for (const auto& solid : solids_)
      if (solid->contains(x)) return TopAbs_IN;
    return TopAbs_OUT;
  }

  PartModelPtr part_;
  double s_;
  TopoDS_Compound shells_;
  mutable std::mutex mutex_;
  mutable BRepExtrema_DistShapeShape distance_;
  std::vector<std::unique_ptr<SolidRays>> solids_;
  std::vector<std::unique_ptr<FaceSearch>> faceSearches_;
};

}  // namespace

PenetrationModelPtr makeReferencePenetration(PartModelPtr part) {
  return std::make_shared<ReferencePenetration>(std::move(part));
}

}  // namespace hg::geometry
