#pragma once
// Limits on BRepMesh, through the progress indicator it asks whether to stop (once a face
// and at each new vertex of its Delaunay triangulation, in OCCT 7.6). Damaged faces found
// by fuzz_brep kept it busy for seconds to minutes, where real parts mesh at once.
#include <BRepMesh_IncrementalMesh.hxx>
#include <IMeshTools_Parameters.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Message_ProgressScope.hxx>
#include <TopoDS_Shape.hxx>

#include <chrono>

namespace hg::geometry {

// Says stop after a fixed number of asks: the same on every machine (the crossing search).
class MeshingBudget final : public Message_ProgressIndicator {
 public:
  explicit MeshingBudget(long checks) : left_(checks) {}
  Standard_Boolean UserBreak() override { return --left_ < 0; }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}
  bool spent() const { return left_ < 0; }

 private:
  long left_;
};

// Says stop once a deadline has passed: it differs between machines, so it decides only
// whether a damaged part gets its mesh at all (the mesh back end).
class MeshingDeadline final : public Message_ProgressIndicator {
 public:
  explicit MeshingDeadline(double seconds)
      : deadline_(std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                          std::chrono::duration<double>(seconds))) {}
  Standard_Boolean UserBreak() override { return passed_ = passed_ || std::chrono::steady_clock::now() > deadline_; }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}
  bool passed() const { return passed_; }

 private:
  std::chrono::steady_clock::time_point deadline_;
  bool passed_ = false;
};

// BRepMesh on `shape` (its faces keep the triangles), on one thread, asking `limit`;
// whether BRepMesh says it is done.
inline bool meshWithin(const TopoDS_Shape& shape, double deflection, double angle,
                       const Handle(Message_ProgressIndicator)& limit) {
  IMeshTools_Parameters parameters;
  parameters.Deflection = deflection;
  parameters.Angle = angle;
  parameters.InParallel = false;
  return BRepMesh_IncrementalMesh(shape, parameters, limit->Start()).IsDone();
}

}  // namespace hg::geometry
