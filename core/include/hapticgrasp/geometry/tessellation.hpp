#pragma once
// A watertight triangle mesh of a part: the input of the mesh and field back ends and of
// the benchmark's surface sampling.
#include <vector>

#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::geometry {

struct Tessellation {
  std::vector<Vec3> vertices;               // metres, part frame, seam nodes welded
  std::vector<Eigen::Vector3i> triangles;   // counter-clockwise seen from outside
  std::vector<int> triangleFace;            // the B-rep face (1-based) each triangle came from
  // Faces BRepMesh could not mesh (a defect the part's load reported): filled from their
  // boundary, as their neighbours discretized it, so that the mesh has no hole.
  std::vector<int> filledFaces;
  double deflection_m = 0;
  Aabb bounds;
  double area() const;
};

// Meshes a copy of the part's shape (the shared model is never modified) with
// BRepMesh_IncrementalMesh at a chord deflection in metres, then welds the nodes that
// faces share along their edges. BRepMesh's deflection is a target, not a strict bound.
Tessellation tessellate(const PartModel& part, double deflection_m, double angularDeflection_rad = 0.3);

}  // namespace hg::geometry
