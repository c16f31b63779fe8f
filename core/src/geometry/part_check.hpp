#pragma once
// What loading decides about a part's solids once they are known to be closed: the B-rep is
// valid (the exact back end answers it), or ShapeFix heals it (the exact back end answers
// the healed shape), or a back end that does not depend on the defect answers it (mesh, or
// field in a build without Embree). Solids of a compound that overlap are measured: the mass
// properties count the overlap twice. Nothing here refuses a part.
#include <TopoDS_Shape.hxx>

#include <string>
#include <vector>

#include "hapticgrasp/geometry/backend.hpp"
#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::geometry {

struct PartCheck {
  TopoDS_Shape solids;                // to keep: as given, or healed
  BackendChoice choice;               // Exact, Mesh or Field, and why
  std::vector<std::string> warnings;  // one line each: overlaps, faces not searched (the choice says the rest)
};

// `solids`: one solid or a compound of solids, each closed and facing outwards;
// metresPerUnit: to state volumes in mm^3.
PartCheck checkPart(const TopoDS_Shape& solids, const PartLoadOptions& options, double metresPerUnit);

}  // namespace hg::geometry
