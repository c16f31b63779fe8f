#include "curve_on_face.hpp"

#include <BRep_Tool.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Pnt2d.hxx>

#include <cmath>

#include "shape_names.hpp"

namespace hg::geometry {
namespace {

bool beyondPeriods(double p, double first, double period) {
  return period > 0 && !(std::abs(p - first) <= kMaxPeriods * period);  // NaN is beyond
}

}  // namespace

bool CurveOnFace::emptyRange() const {
  return !(std::isfinite(first) && std::isfinite(last) && last - first > Precision::PConfusion());
}

bool CurveOnFace::runsRound() const {
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
  if (surface.IsNull() || emptyRange()) return false;
  const double uPeriod = surface->IsUPeriodic() ? surface->UPeriod() : 0;
  const double vPeriod = surface->IsVPeriodic() ? surface->VPeriod() : 0;
  if (uPeriod == 0 && vPeriod == 0) return false;
  double u1 = 0, u2 = 0, v1 = 0, v2 = 0;
  surface->Bounds(u1, u2, v1, v2);
  constexpr int kSamples = 8;
  for (int i = 0; i <= kSamples; ++i) {
    const gp_Pnt2d uv = curve->Value(first + (last - first) * i / kSamples);
    if (beyondPeriods(uv.X(), u1, uPeriod) || beyondPeriods(uv.Y(), v1, vPeriod)) return true;
  }
  return false;
}

std::string firstCurveOnFace(const TopoDS_Shape& shape, const std::function<std::string(const CurveOnFace&)>& why) {
  for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next()) {
    for (TopExp_Explorer e(f.Current(), TopAbs_EDGE); e.More(); e.Next()) {
      CurveOnFace c{TopoDS::Edge(e.Current()), TopoDS::Face(f.Current()), {}, 0, 0};
      std::string answer;
      try {
        c.curve = BRep_Tool::CurveOnSurface(c.edge, c.face, c.first, c.last);
        if (c.curve.IsNull()) continue;
        answer = why(c);
      } catch (const Standard_Failure&) {
        answer = "cannot be evaluated";
      }
      if (!answer.empty()) return subShapeName(shape, c.edge) + " " + answer + " on " + subShapeName(shape, c.face);
    }
  }
  return "";
}

std::string runawayCurveOnFace(const TopoDS_Shape& shape) {
  return firstCurveOnFace(shape, [](const CurveOnFace& c) -> std::string {
    return c.runsRound() ? "runs more than " + std::to_string(static_cast<int>(kMaxPeriods)) + " times round" : "";
  });
}

}  // namespace hg::geometry
