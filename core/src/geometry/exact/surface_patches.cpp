#include "surface_patches.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace hg::geometry::exact {
namespace {

// Samples per side of a rectangle under analysis, (grid + 1)^2 in all: a quick look decides
// most cuts, the full one makes the patch (and may still call for a cut).
constexpr int kQuickGrid = 2, kFullGrid = 4;

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

// What the samples of one rectangle say about it.
struct Analysis {
  double turnU = 0, turnV = 0;  // largest normal turn along u lines and along v lines
  double maxTurn = 0;           // largest angle between a sample normal and the mean
  SurfacePatch patch;
};

// The principal curvatures at a regular point, signed: positive where the surface bends
// towards n (its centre of curvature lies on n's side).
struct Principal {
  double k1 = 0, k2 = 0;
};

Principal principalCurvatures(const gp_Vec& du, const gp_Vec& dv, const gp_Vec& duu, const gp_Vec& dvv,
                              const gp_Vec& duv, const gp_Vec& n) {
  const double E = du.Dot(du), F = du.Dot(dv), G = dv.Dot(dv);
  const double L = duu.Dot(n), M = duv.Dot(n), N = dvv.Dot(n);
  const double det = E * G - F * F;
  if (!(det > 0)) return {};
  const double K = (L * N - M * M) / det, H = (E * N - 2 * F * M + G * L) / (2 * det);
  const double root = std::sqrt(std::max(0.0, H * H - K));
  return {H + root, H - root};
}

Analysis analyse(const SurfaceD2& surface, const UvRect& r, double tolerance, int kGrid) {
  Analysis a;
  a.patch.rect = r;
  gp_Pnt p[kFullGrid + 1][kFullGrid + 1];
  gp_Vec normal[kFullGrid + 1][kFullGrid + 1];
  bool regular[kFullGrid + 1][kFullGrid + 1];
  double maxSu = 0, maxSv = 0, maxSuu = 0, maxSvv = 0, maxSuv = 0;
  Principal extreme;  // the largest curvature towards n and against it (as -k)

  gp_Vec mean(0, 0, 0);
  const double hu = r.du() / kGrid, hv = r.dv() / kGrid;
  const bool full = kGrid == kFullGrid;
  for (int i = 0; i <= kGrid; ++i)
    for (int j = 0; j <= kGrid; ++j) {
      gp_Vec su, sv, suu, svv, suv;
      surface(r.u0 + i * hu, r.v0 + j * hv, p[i][j], su, sv, suu, svv, suv);
      maxSu = std::max(maxSu, su.Magnitude());
      maxSv = std::max(maxSv, sv.Magnitude());
      maxSuu = std::max(maxSuu, suu.Magnitude());
      maxSvv = std::max(maxSvv, svv.Magnitude());
      maxSuv = std::max(maxSuv, suv.Magnitude());
      gp_Vec n = su.Crossed(sv);
      const double m = n.Magnitude();
      // A pole (a degenerate side of the box) has no normal; its neighbours decide.
      regular[i][j] = m > 1e-9 * su.Magnitude() * sv.Magnitude() && m > 0;
      if (regular[i][j]) {
        n /= m;
        normal[i][j] = n;
        mean += n;
        // Signed against one common orientation (the first sample's): on a patch the
        // normal turns by less than a right angle, so the sides agree.
        const Principal k = principalCurvatures(su, sv, suu, svv, suv, n);
        extreme.k1 = std::max({extreme.k1, k.k1, k.k2});
        extreme.k2 = std::max({extreme.k2, -k.k1, -k.k2});
      }
    }
  auto angle = [](const gp_Vec& a, const gp_Vec& b) { return std::acos(std::clamp(a.Dot(b), -1.0, 1.0)); };
  for (int i = 0; i <= kGrid; ++i)
    for (int j = 0; j <= kGrid; ++j) {
      if (!regular[i][j]) continue;
      if (i < kGrid && regular[i + 1][j]) a.turnU = std::max(a.turnU, angle(normal[i][j], normal[i + 1][j]) * kGrid);
      if (j < kGrid && regular[i][j + 1]) a.turnV = std::max(a.turnV, angle(normal[i][j], normal[i][j + 1]) * kGrid);
    }
  const double meanNorm = mean.Magnitude();
  if (meanNorm > 0) mean /= meanNorm;
  for (int i = 0; i <= kGrid; ++i)
    for (int j = 0; j <= kGrid; ++j)
      if (regular[i][j]) a.maxTurn = std::max(a.maxTurn, meanNorm > 0 ? angle(mean, normal[i][j]) : M_PI);

  // Between samples the surface leaves their hull by at most the bilinear interpolation
  // error, (hu^2 |S_uu| + 2 hu hv |S_uv| + hv^2 |S_vv|) / 8; the second derivatives are
  // sampled too, so the margin is doubled.
  const double sag = 0.25 * (hu * hu * maxSuu + 2 * hu * hv * maxSuv + hv * hv * maxSvv) + tolerance;
  std::vector<Vec3> points;
  points.reserve((kGrid + 1) * (kGrid + 1));
  for (int i = 0; i <= kGrid; ++i)
    for (int j = 0; j <= kGrid; ++j) points.push_back(toVec(p[i][j].XYZ()));
  // The oriented box over the patch's mean normal: a thin slab where it is nearly flat.
  const bool flat = meanNorm > 0 && a.maxTurn < M_PI / 2;
  LeafBound& bound = a.patch.bound;
  bound = LeafBound::around(points, flat ? toVec(mean.XYZ()) : Vec3::Zero(), true, sag);
  a.patch.searchedCentre = bound.centre;
  a.patch.searchedHalfThickness = bound.oriented() ? bound.half.z() : 0;
  a.patch.turn = a.maxTurn;
  // Sampled curvature: with a margin, as it may peak between samples.
  a.patch.kTowards = 1.1 * extreme.k1;
  a.patch.kAway = 1.1 * extreme.k2;
  // The ranges of N's components in the patch's frame and of (c - P).N, from the samples;
  // between samples N turns by at most k times half the spacing.
  if (bound.oriented()) {
    const double spacing = std::max(hu * maxSu, hv * maxSv);
    const double turnSlack = 0.5 * spacing * std::max(a.patch.kTowards, a.patch.kAway) + 1e-9;
    Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
    double hLo = INFINITY, hHi = -INFINITY, reach = 0;
    for (int i = 0; i <= kGrid; ++i)
      for (int j = 0; j <= kGrid; ++j) {
        if (!regular[i][j]) continue;
        const Vec3 n = toVec(normal[i][j].XYZ()), local = bound.axes.transpose() * n;
        lo = lo.cwiseMin(local);
        hi = hi.cwiseMax(local);
        const double h = (bound.centre - toVec(p[i][j].XYZ())).dot(n);
        hLo = std::min(hLo, h);
        hHi = std::max(hHi, h);
        reach = std::max(reach, (bound.centre - toVec(p[i][j].XYZ())).norm());
      }
    a.patch.normalLo = lo - Vec3::Constant(turnSlack);
    a.patch.normalHi = hi + Vec3::Constant(turnSlack);
    a.patch.heightLo = hLo - reach * turnSlack - sag;
    a.patch.heightHi = hHi + reach * turnSlack + sag;
  }
  a.patch.maxSuu = 2 * maxSuu;
  a.patch.maxSuv = 2 * maxSuv;
  a.patch.maxSvv = 2 * maxSvv;
  a.patch.lipschitzU = 1.25 * (maxSu + 0.5 * (hu * maxSuu + hv * maxSuv));
  a.patch.lipschitzV = 1.25 * (maxSv + 0.5 * (hv * maxSvv + hu * maxSuv));
  const double at[SurfacePatch::kSeeds][2] = {{0.5, 0.5}, {0.25, 0.25}, {0.75, 0.25}, {0.25, 0.75}, {0.75, 0.75}};
  for (int k = 0; full && k < SurfacePatch::kSeeds; ++k) {
    SurfaceJet& s = a.patch.seeds[k];
    s.u = r.u0 + r.du() * at[k][0];
    s.v = r.v0 + r.dv() * at[k][1];
    surface(s.u, s.v, s.p, s.du, s.dv, s.duu, s.dvv, s.duv);
  }
  for (const Vec3& q : points) a.patch.spread = std::max(a.patch.spread, (q - bound.centre).norm());
  a.patch.spread += sag;
  return a;
}

std::vector<double> cuts(double lo, double hi, const std::vector<double>& breaks) {
  std::vector<double> c{lo};
  const double eps = 1e-9 * (hi - lo);
  for (double b : breaks)
    if (b > c.back() + eps && b < hi - eps) c.push_back(b);
  c.push_back(hi);
  return c;
}

}  // namespace

std::vector<SurfacePatch> buildSurfacePatches(const SurfaceD2& surface, const UvRect& box,
                                              const std::vector<double>& uBreaks,
                                              const std::vector<double>& vBreaks, const PatchOptions& options) {
  std::vector<double> us = uBreaks, vs = vBreaks;
  std::sort(us.begin(), us.end());
  std::sort(vs.begin(), vs.end());
  const std::vector<double> uc = cuts(box.u0, box.u1, us), vc = cuts(box.v0, box.v1, vs);
  // Breadth first, so that a face that runs out of patches is cut evenly.
  struct Todo {
    UvRect rect;
    int depth;
  };
  std::deque<Todo> todo;
  for (std::size_t i = 0; i + 1 < uc.size(); ++i)
    for (std::size_t j = 0; j + 1 < vc.size(); ++j) todo.push_back({{uc[i], uc[i + 1], vc[j], vc[j + 1]}, 0});
  std::vector<SurfacePatch> patches;
  while (!todo.empty()) {
    const auto [r, depth] = todo.front();
    todo.pop_front();
    // A patch is cut while its normal turns too much, or while it is long for its
    // curvature (a strip along a cylinder-like surface: its focal distance, not its turn,
    // is then what limits a certain Newton search). Around a pole the normal turns
    // whatever the size: the depth stops the cutting there. A quick look decides most
    // cuts; what it would keep is analysed in full, and may still be cut.
    // Its size counts only along the directions the surface bends in: a strip along a
    // straight line of the surface (a cylinder's) may stay long; its focal test holds.
    auto curvedSpread = [&](const Analysis& b) {
      const bool bendsU = b.turnU > options.straightTurn_rad, bendsV = b.turnV > options.straightTurn_rad;
      if (bendsU && bendsV) return b.patch.spread;
      const double halfU = 0.4 * b.patch.lipschitzU * b.patch.rect.du(), halfV = 0.4 * b.patch.lipschitzV * b.patch.rect.dv();
      return bendsU ? halfU : bendsV ? halfV : 0.0;
    };
    auto wantsCut = [&](const Analysis& b) {
      return b.maxTurn > options.maxTurn_rad ||
             curvedSpread(b) * std::max(b.patch.kTowards, b.patch.kAway) > options.maxSpreadCurvature;
    };
    const bool room = patches.size() + todo.size() + 2 <= static_cast<std::size_t>(options.maxPatches);
    const bool mayCut = room && depth < options.maxDepth;
    Analysis a = analyse(surface, r, options.tolerance, kQuickGrid);
    if (!(mayCut && wantsCut(a))) a = analyse(surface, r, options.tolerance, kFullGrid);
    if (mayCut && wantsCut(a)) {
      // Halve across the direction the normal turns most along, or else the longer one.
      const bool acrossU = a.maxTurn > options.maxTurn_rad ? a.turnU >= a.turnV
                           : a.turnV <= options.straightTurn_rad ? true
                           : a.turnU <= options.straightTurn_rad ? false
                                                                 : a.patch.lipschitzU * r.du() >= a.patch.lipschitzV * r.dv();
      if (acrossU) {
        const double m = 0.5 * (r.u0 + r.u1);
        todo.push_back({{r.u0, m, r.v0, r.v1}, depth + 1});
        todo.push_back({{m, r.u1, r.v0, r.v1}, depth + 1});
      } else {
        const double m = 0.5 * (r.v0 + r.v1);
        todo.push_back({{r.u0, r.u1, r.v0, m}, depth + 1});
        todo.push_back({{r.u0, r.u1, m, r.v1}, depth + 1});
      }
      continue;
    }
    patches.push_back(a.patch);
  }
  return patches;
}

}  // namespace hg::geometry::exact
