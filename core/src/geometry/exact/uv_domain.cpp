#include "uv_domain.hpp"

#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <GCE2d_MakeSegment.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>

#include <algorithm>
#include <cmath>

namespace hg::geometry::exact {
namespace {
constexpr int kSamples = 64;     // per pcurve, to find where v turns
constexpr int kSubdivisions = 8;  // per monotone piece: small boxes settle most rays unsolved
constexpr int kBins = 64;
}  // namespace

UvDomain::UvDomain(const TopoDS_Face& face) {
  for (TopExp_Explorer wires(face, TopAbs_WIRE); wires.More(); wires.Next()) addWire(TopoDS::Wire(wires.Current()), face);
  buildBins();
}

// A valid face's pcurves need only meet within the edges' tolerance: consecutive ones may
// leave gaps in (u, v) (0.004 in v on a makeThickness offset face of the corpus). A ray
// through a gap would cross one curve of the pair and not the other and flip the answer
// over a whole band of v, so the loop is closed with straight bridges across each gap.
void UvDomain::addWire(const TopoDS_Wire& wire, const TopoDS_Face& face) {
  struct Pcurve {
    Handle(Geom2d_Curve) curve;
    double first, last;
    bool forward;
  };
  auto pcurveOf = [&face](const TopoDS_Edge& edge) {
    Pcurve p;
    p.curve = BRep_Tool::CurveOnSurface(edge, face, p.first, p.last);
    p.forward = edge.Orientation() != TopAbs_REVERSED;
    return p;
  };
  int edges = 0;
  for (TopExp_Explorer ex(wire, TopAbs_EDGE); ex.More(); ex.Next()) ++edges;
  std::vector<Pcurve> loop;
  for (BRepTools_WireExplorer ex(wire, face); ex.More(); ex.Next()) loop.push_back(pcurveOf(ex.Current()));
  const bool ordered = static_cast<int>(loop.size()) == edges;
  if (!ordered) {  // the explorer could not order the wire: take its edges as they come
    loop.clear();
    for (TopExp_Explorer ex(wire, TopAbs_EDGE); ex.More(); ex.Next()) loop.push_back(pcurveOf(TopoDS::Edge(ex.Current())));
  }
  std::vector<gp_Pnt2d> starts, ends;
  for (const Pcurve& p : loop) {
    if (p.curve.IsNull()) continue;
    addCurve(p.curve, p.first, p.last);
    starts.push_back(p.curve->Value(p.forward ? p.first : p.last));
    ends.push_back(p.curve->Value(p.forward ? p.last : p.first));
  }
  if (!ordered || starts.size() != loop.size()) return;
  // A gap as wide as the wire itself is no tolerance gap (a pcurve given a period away):
  // bridging it would cut the domain in two.
  double uLow = INFINITY, uHigh = -INFINITY, vLow = INFINITY, vHigh = -INFINITY;
  for (const gp_Pnt2d& p : starts) {
    uLow = std::min(uLow, p.X()), uHigh = std::max(uHigh, p.X());
    vLow = std::min(vLow, p.Y()), vHigh = std::max(vHigh, p.Y());
  }
  const double widest = 0.05 * std::hypot(uHigh - uLow, vHigh - vLow);
  for (std::size_t i = 0; i < ends.size(); ++i) {
    const gp_Pnt2d& from = ends[i];
    const gp_Pnt2d& to = starts[(i + 1) % starts.size()];
    const double scale = 1 + std::max(std::abs(from.X()), std::abs(from.Y()));
    const double gap = from.Distance(to);
    if (gap <= 1e-12 * scale || gap > widest) continue;
    const Handle(Geom2d_TrimmedCurve) bridge = GCE2d_MakeSegment(from, to).Value();
    addCurve(bridge, bridge->FirstParameter(), bridge->LastParameter());
  }
}

// Cuts the pcurve where dv/dt changes sign (found on samples, refined by bisection).
void UvDomain::addCurve(const Handle(Geom2d_Curve)& curve, double first, double last) {
  curves_.push_back(curve);
  const Geom2d_Curve* c = curve.get();
  auto dv = [c](double t) {
    gp_Pnt2d p;
    gp_Vec2d d;
    c->D1(t, p, d);
    return d.Y();
  };
  std::vector<double> cuts{first};
  double previous = dv(first);
  for (int i = 1; i <= kSamples; ++i) {
    const double t = first + (last - first) * i / kSamples;
    const double current = dv(t);
    if (previous * current < 0) {
      double a = first + (last - first) * (i - 1) / kSamples, b = t;
      for (int k = 0; k < 60; ++k) {
        const double m = 0.5 * (a + b);
        (dv(a) * dv(m) <= 0 ? b : a) = m;
      }
      cuts.push_back(0.5 * (a + b));
    }
    if (current != 0) previous = current;
  }
  cuts.push_back(last);
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
    for (int k = 0; k < kSubdivisions; ++k) {
      const double a = cuts[i] + (cuts[i + 1] - cuts[i]) * k / kSubdivisions;
      const double b = cuts[i] + (cuts[i + 1] - cuts[i]) * (k + 1) / kSubdivisions;
      addPiece(c, a, b);
    }
}

void UvDomain::addPiece(const Geom2d_Curve* c, double t0, double t1) {
  Piece piece{c, t0, t1, INFINITY, -INFINITY, INFINITY, -INFINITY, false};
  for (int k = 0; k <= 16; ++k) {
    const gp_Pnt2d p = c->Value(t0 + (t1 - t0) * k / 16);
    piece.uLow = std::min(piece.uLow, p.X());
    piece.uHigh = std::max(piece.uHigh, p.X());
  }
  const double va = c->Value(t0).Y(), vb = c->Value(t1).Y();
  piece.vLow = std::min(va, vb);
  piece.vHigh = std::max(va, vb);
  piece.increasing = vb > va;
  // Between samples u may bulge a little beyond them: widen the box; the root decides.
  const double margin = 0.1 * (piece.uHigh - piece.uLow) + 1e-9 * (1 + std::abs(piece.uHigh));
  piece.uLow -= margin;
  piece.uHigh += margin;
  const double vMargin = 0.1 * (piece.vHigh - piece.vLow) + 1e-9 * (1 + std::abs(piece.vHigh));
  boundaryBoxes_.push_back({piece.uLow, piece.uHigh, piece.vLow - vMargin, piece.vHigh + vMargin});
  if (piece.vHigh > piece.vLow) pieces_.push_back(piece);  // a piece of constant v is never crossed
}

void UvDomain::buildBins() {
  if (pieces_.empty()) return;
  vMin_ = INFINITY;
  vMax_ = -INFINITY;
  for (const Piece& p : pieces_) {
    vMin_ = std::min(vMin_, p.vLow);
    vMax_ = std::max(vMax_, p.vHigh);
  }
  bins_.assign(kBins, {});
  const double width = (vMax_ - vMin_) / kBins;
  for (int i = 0; i < static_cast<int>(pieces_.size()); ++i) {
    const int a = std::clamp(static_cast<int>((pieces_[i].vLow - vMin_) / width), 0, kBins - 1);
    const int b = std::clamp(static_cast<int>((pieces_[i].vHigh - vMin_) / width), 0, kBins - 1);
    for (int k = a; k <= b; ++k) bins_[k].push_back(i);
  }
}

// Does the ray from (u, v) towards +u cross the piece? Half-open in v, so that a ray
// through the point where two pieces meet counts one crossing, not two.
bool UvDomain::crosses(const Piece& piece, double u, double v) const noexcept {
  if (v < piece.vLow || v >= piece.vHigh) return false;
  if (u < piece.uLow) return true;
  if (u > piece.uHigh) return false;
  // v(t) = v0 on a monotone piece: Illinois regula falsi (superlinear, bracketing).
  double a = piece.t0, b = piece.t1;
  double fa = piece.curve->Value(a).Y() - v, fb = piece.curve->Value(b).Y() - v;
  double t = a;
  for (int k = 0; k < 60; ++k) {
    if (fb == fa) break;
    t = b - fb * (b - a) / (fb - fa);
    const double ft = piece.curve->Value(t).Y() - v;
    if (ft == 0) break;
    if ((ft < 0) != (fb < 0)) {
      a = b;
      fa = fb;
    } else {
      fa *= 0.5;
    }
    b = t;
    fb = ft;
    if (std::abs(b - a) <= 1e-15 * (1 + std::abs(a) + std::abs(b))) break;
  }
  return piece.curve->Value(t).X() > u;
}

bool UvDomain::contains(double u, double v) const noexcept {
  if (pieces_.empty() || v < vMin_ || v > vMax_) return false;
  const int bin = std::clamp(static_cast<int>((v - vMin_) / (vMax_ - vMin_) * kBins), 0, kBins - 1);
  bool inside = false;
  for (const int i : bins_[bin])
    if (crosses(pieces_[i], u, v)) inside = !inside;
  return inside;
}

bool UvDomain::rectOutside(double u0, double u1, double v0, double v1) const noexcept {
  for (const Box& b : boundaryBoxes_)
    if (b.u0 <= u1 && b.u1 >= u0 && b.v0 <= v1 && b.v1 >= v0) return false;
  return !contains(0.5 * (u0 + u1), 0.5 * (v0 + v1));
}

std::size_t UvDomain::memoryBytes() const noexcept {
  std::size_t bytes = sizeof(*this) + pieces_.capacity() * sizeof(Piece) + boundaryBoxes_.capacity() * sizeof(Box);
  for (const auto& b : bins_) bytes += b.capacity() * sizeof(int);
  return bytes;
}

}  // namespace hg::geometry::exact
