#pragma once
// Limits on BRepMesh: through the progress indicator it asks whether to stop (once a face
// and at each new vertex of its Delaunay triangulation, in OCCT 7.6), and, for the work it
// does before it asks, by failing the faces whose grid of nodes would be too large. Damaged faces
// found by fuzz_brep kept it busy for seconds to minutes, where real parts mesh at once.
#include <BRepMesh_IncrementalMesh.hxx>
#include <IMeshTools_Parameters.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Message_ProgressScope.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <chrono>
#include <vector>

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

// What BRepMesh is asked for: chord and angular deflection, in the shape's units and radians.
struct MeshingParameters {
  double deflection;
  double angle;
  double minSize() const;  // as BRepMesh_IncrementalMesh sets it: a tenth of the deflection
};

// A face whose grid BRepMesh would lay with more nodes than this is not meshed. On a cylinder,
// cone, sphere or torus BRepMesh's range splitter lays a grid of nodes over the span of the
// face's edge points before it asks the progress indicator anything, and on a cone
// BRepMesh_ModelPreProcessor first puts a point at every V step along the seam. A damaged
// cone whose edge points span no U (fuzz_brep) made that step 0/0, cast to int: 1e-8 of its
// range, and BRepMesh took more than 8 GB in a minute. A real part's face needs thousands of
// nodes; the sample parts stay below 10^5 per face at 0.01 mm (test_meshing_limits).
constexpr double kMaxSurfaceGridNodes = 2e6;

// Grids BRepMesh would lay over the faces of `shape`, as its own model of the shape (edges
// discretized, wires healed) gives their spans and deflections.
struct SurfaceGrids {
  std::vector<TopoDS_Face> beyondTheLimit;  // faces beyond kMaxSurfaceGridNodes (or unbounded)
  double largest = 0;                       // nodes of the largest grid within it
};
SurfaceGrids surfaceGrids(const TopoDS_Shape& shape, const MeshingParameters& parameters);

// BRepMesh on `shape` (its faces keep the triangles), on one thread, asking `limit` if it is
// not null, with the faces beyond kMaxSurfaceGridNodes left without triangles.
struct MeshedFaces {
  bool done;                                // BRepMesh says it is done
  std::vector<TopoDS_Face> beyondTheLimit;  // left without triangles
};
MeshedFaces meshWithin(const TopoDS_Shape& shape, const MeshingParameters& parameters,
                       const Handle(Message_ProgressIndicator)& limit);

}  // namespace hg::geometry
