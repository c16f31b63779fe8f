#pragma once
// Solids of one part (a compound: a bolt in its nut, a weldment) whose volumes overlap: the
// part's mass properties count the overlap twice.
#include <TopoDS_Shape.hxx>

#include <set>
#include <utility>
#include <vector>

namespace hg::geometry {

struct SolidOverlap {
  int a = 0, b = 0;       // 1-based solids, TopExp::MapShapes order, a < b
  double volume = -1;     // shape units^3; < 0: not measured (BRepAlgoAPI_Common failed)
};

// `crossing`: the pairs of solids whose boundaries cross (FaceCrossings between solids);
// each overlaps. Pairs whose boundaries do not cross overlap when one lies inside the
// other: one of its points is classified inside the other. Each overlap is measured with
// BRepAlgoAPI_Common, at most `maxMeasured` of them (the rest are not measured).
std::vector<SolidOverlap> findSolidOverlaps(const TopoDS_Shape& solids, const std::set<std::pair<int, int>>& crossing,
                                            int maxMeasured = 16);

}  // namespace hg::geometry
