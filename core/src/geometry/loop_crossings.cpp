#include "loop_crossings.hpp"

#include <gp_Ax3.hxx>
#include <gp_XY.hxx>

#include <algorithm>
#include <cmath>

namespace hg::geometry {
namespace {

// Where a segment is cut: at `along` (0..1 from its start) by crossing number `crossing`.
struct Cut {
  double along;
  int crossing;
};

// A point of the loop as the walk meets it: a corner of the loop (crossing -1) or a crossing.
struct Stop {
  gp_XYZ point;
  int crossing;
};

}  // namespace

std::vector<Polyline> cutAtCrossings(const Polyline& loop, const gp_Dir& normal) {
  const std::size_t n = loop.size();
  if (n < 4) return n < 3 ? std::vector<Polyline>{} : std::vector<Polyline>{loop};  // a triangle cannot cross itself

  // Seen along the normal: the loop in a frame of its plane.
  const gp_Ax3 frame(gp_Pnt(0, 0, 0), normal);
  const gp_XYZ ex = frame.XDirection().XYZ(), ey = frame.YDirection().XYZ();
  std::vector<gp_XY> flat(n);
  for (std::size_t i = 0; i < n; ++i) flat[i] = gp_XY(loop[i].Dot(ex), loop[i].Dot(ey));

  // Every proper crossing of two segments that share no corner: segment i runs from point i
  // to point i + 1. O(n^2), once per defective face at load. Segments that only touch, or
  // overlap along a line, are left alone: they bound no lobe.
  std::vector<std::vector<Cut>> cuts(n);
  std::vector<gp_XYZ> crossings;
  for (std::size_t i = 0; i < n; ++i) {
    const gp_XY a = flat[i], r = flat[(i + 1) % n] - a;
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the closing point
      const gp_XY c = flat[j], s = flat[(j + 1) % n] - c;
      const double denominator = r ^ s;
      if (std::abs(denominator) <= 1e-12 * r.Modulus() * s.Modulus()) continue;  // parallel
      const double t = ((c - a) ^ s) / denominator, w = ((c - a) ^ r) / denominator;
      if (!(t > 0 && t < 1 && w > 0 && w < 1)) continue;
      const int crossing = static_cast<int>(crossings.size());
      crossings.push_back(loop[i] + (loop[(i + 1) % n] - loop[i]) * t);
      cuts[i].push_back({t, crossing});
      cuts[j].push_back({w, crossing});
    }
  }
  if (crossings.empty()) return {loop};

  // Walk the loop through its crossings; each crossing is met twice. Coming back to one
  // closes a loop: what was walked since it is cut off, and the crossing stays behind as a
  // corner of what is left. What is left at the end is the last loop.
  std::vector<Polyline> loops;
  std::vector<Stop> path;
  std::vector<int> at(crossings.size(), -1);  // where each crossing stands in `path`, -1 if not
  auto meet = [&](const Stop& stop) {
    if (stop.crossing >= 0 && at[stop.crossing] >= 0) {
      const std::size_t from = static_cast<std::size_t>(at[stop.crossing]);
      Polyline closed;
      for (std::size_t k = from; k < path.size(); ++k) {
        closed.push_back(path[k].point);
        if (k > from && path[k].crossing >= 0) at[path[k].crossing] = -1;
      }
      if (closed.size() >= 3) loops.push_back(std::move(closed));
      path.resize(from + 1);
      at[stop.crossing] = -1;  // met twice: done
      return;
    }
    if (stop.crossing >= 0) at[stop.crossing] = static_cast<int>(path.size());
    path.push_back(stop);
  };
  for (std::size_t i = 0; i < n; ++i) {
    meet({loop[i], -1});
    std::sort(cuts[i].begin(), cuts[i].end(), [](const Cut& x, const Cut& y) { return x.along < y.along; });
    for (const Cut& cut : cuts[i]) meet({crossings[cut.crossing], cut.crossing});
  }
  Polyline rest;
  for (const Stop& stop : path) rest.push_back(stop.point);
  if (rest.size() >= 3) loops.push_back(std::move(rest));
  return loops;
}

}  // namespace hg::geometry
