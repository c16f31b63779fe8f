// The reference back end: OCCT's own answer, used as the truth in tests and benchmarks.
// BRepExtrema_DistShapeShape against the shells (against a solid it answers 0 for every
// point inside) and BRepClass3d_SolidClassifier for the sign. Both keep what they
// precompute about the part (boxes of the faces, the solid explorer) across queries, so
// that the ladder compares against OCCT at its best; that state is mutable, so queries
// are serialised with a mutex. Slow, and it allocates: never on the servo thread.
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
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
      classifiers_.push_back(std::make_unique<BRepClass3d_SolidClassifier>(ex.Current()));
    distance_.LoadS2(shells_);
    distance_.SetFlag(Extrema_ExtFlag_MIN);
  }

  std::string_view name() const noexcept override { return "reference"; }
  std::string setting() const override { return "BRepExtrema + classifier"; }
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
      const gp_Pnt foot = distance.PointOnShape2(1);
      const double d = distance.Value();
      p.inside = d > 0 && classify(x) == TopAbs_IN;
      p.depth = (p.inside ? d : -d) * s_;
      p.foot = toVec(foot.XYZ()) * s_;
      p.vector = toVec(gp_Vec(foot, x).XYZ()) * s_;
      if (d > 0) p.normal = (p.inside ? -p.vector : p.vector).normalized();
      const TopoDS_Shape support = distance.SupportOnShape2(1);
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
  TopAbs_State classify(const gp_Pnt& x) const {
    for (const auto& classifier : classifiers_) {
      classifier->Perform(x, 1e-9 * part_->characteristicLength() / s_);
      if (classifier->State() == TopAbs_IN) return TopAbs_IN;
    }
    return TopAbs_OUT;
  }

  PartModelPtr part_;
  double s_;
  TopoDS_Compound shells_;
  mutable std::mutex mutex_;
  mutable BRepExtrema_DistShapeShape distance_;
  std::vector<std::unique_ptr<BRepClass3d_SolidClassifier>> classifiers_;
};

}  // namespace

PenetrationModelPtr makeReferencePenetration(PartModelPtr part) {
  return std::make_shared<ReferencePenetration>(std::move(part));
}

}  // namespace hg::geometry
