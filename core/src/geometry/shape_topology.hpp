#pragma once
// Is a shell or solid closed? Every edge must bound exactly two of its faces.
#include <TopoDS_Shape.hxx>

namespace hg::geometry {

struct UnsharedEdges {
  int free = 0;         // bound by one face only (seams and degenerated edges excepted): holes
  int nonManifold = 0;  // bound by more than two faces
};

// Within one shell or solid (solids of a compound may share edges: check each alone).
UnsharedEdges edgesNotShared(const TopoDS_Shape& shellOrSolid);

}  // namespace hg::geometry
