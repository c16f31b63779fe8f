#pragma once
// A face's boundary loop that crosses itself (a defect BRepCheck calls a self-intersecting
// wire) bounds no region by itself: the region it means is where its planar winding number
// is not 0, counted with that number. Cut at its crossings into loops that do not cross,
// it becomes loops whose regions add up to that count: each counts +1 if it runs as the
// outline does, -1 if it runs the other way (a lobe the outline turns over).
#include <gp_Dir.hxx>
#include <gp_XYZ.hxx>

#include <vector>

namespace hg::geometry {

using Polyline = std::vector<gp_XYZ>;

// `loop`: a closed polyline (its last point joins its first), nearly planar about
// `normal`. Returns it cut at every point where two of its segments cross (seen along
// `normal`) into closed polylines that do not cross themselves; each crossing point is a
// corner of both loops that meet there, the same gp_XYZ in both. A loop that does not
// cross itself comes back whole; loops of fewer than 3 points are left out.
std::vector<Polyline> cutAtCrossings(const Polyline& loop, const gp_Dir& normal);

}  // namespace hg::geometry
