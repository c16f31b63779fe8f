#include "curve_pieces.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace hg::geometry::exact {
namespace {

constexpr int kSamples = 8;  // intervals per piece under analysis

struct Analysis {
  double turn = 0;  // total tangent turn along the piece
  CurvePiece piece;
};

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

Analysis analyse(const CurveD2& curve, double t0, double t1, double tolerance) {
  Analysis a;
  CurvePiece& piece = a.piece;
  piece.t0 = t0;
  piece.t1 = t1;
  const double h = (t1 - t0) / kSamples;
  double maxD1 = 0, maxD2 = 0;
  gp_Vec previous;
  bool havePrevious = false;
  std::vector<Vec3> points;
  for (int i = 0; i <= kSamples; ++i) {
    gp_Pnt p;
    gp_Vec d1, d2;
    curve(t0 + i * h, p, d1, d2);
    points.push_back(toVec(p.XYZ()));
    const double speed = d1.Magnitude();
    maxD1 = std::max(maxD1, speed);
    maxD2 = std::max(maxD2, d2.Magnitude());
    if (speed > 0) {
      piece.kappa = std::max(piece.kappa, d1.Crossed(d2).Magnitude() / (speed * speed * speed));
      const gp_Vec tangent = d1 / speed;
      if (havePrevious) a.turn += std::acos(std::clamp(tangent.Dot(previous), -1.0, 1.0));
      previous = tangent;
      havePrevious = true;
    }
  }
  piece.kappa *= 1.1;  // sampled: it may peak between samples
  // Between samples the curve leaves their hull by at most h^2 |C''| / 8: doubled, as
  // |C''| is sampled too.
  const double sag = 0.25 * h * h * maxD2 + tolerance;
  piece.bound = LeafBound::around(points, points.back() - points.front(), false, sag);
  piece.lipschitz = 1.25 * (maxD1 + 0.5 * h * maxD2);
  piece.maxD2 = 2 * maxD2;  // sampled: it may peak between samples
  for (int k = 0; k < CurvePiece::kSeeds; ++k) {
    gp_Vec d1, d2;
    piece.seedT[k] = t0 + (t1 - t0) * (2 * k + 1) / (2.0 * CurvePiece::kSeeds);
    curve(piece.seedT[k], piece.seedP[k], d1, d2);
  }
  for (const Vec3& q : points) piece.spread = std::max(piece.spread, (q - piece.bound.centre).norm());
  piece.spread += sag;
  return a;
}

}  // namespace

std::vector<CurvePiece> buildCurvePieces(const CurveD2& curve, double t0, double t1, const std::vector<double>& breaks,
                                         const PieceOptions& options) {
  std::vector<double> cuts{t0};
  std::vector<double> sorted = breaks;
  std::sort(sorted.begin(), sorted.end());
  const double eps = 1e-9 * (t1 - t0);
  for (double b : sorted)
    if (b > cuts.back() + eps && b < t1 - eps) cuts.push_back(b);
  cuts.push_back(t1);
  struct Todo {
    double t0, t1;
    int depth;
  };
  std::deque<Todo> todo;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) todo.push_back({cuts[i], cuts[i + 1], 0});
  std::vector<CurvePiece> pieces;
  while (!todo.empty()) {
    const Todo t = todo.front();
    todo.pop_front();
    Analysis a = analyse(curve, t.t0, t.t1, options.tolerance);
    const bool room = pieces.size() + todo.size() + 2 <= static_cast<std::size_t>(options.maxPieces);
    // Cut while the tangent turns too much or the piece is long for its curvature.
    const bool long_ = a.piece.spread * a.piece.kappa > options.maxSpreadCurvature;
    if (room && t.depth < options.maxDepth && (a.turn > options.maxTurn_rad || long_)) {
      const double m = 0.5 * (t.t0 + t.t1);
      todo.push_back({t.t0, m, t.depth + 1});
      todo.push_back({m, t.t1, t.depth + 1});
      continue;
    }
    pieces.push_back(a.piece);
  }
  std::sort(pieces.begin(), pieces.end(), [](const CurvePiece& a, const CurvePiece& b) { return a.t0 < b.t0; });
  return pieces;
}

}  // namespace hg::geometry::exact
