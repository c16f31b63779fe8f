#include "curve_on_face.hpp"

#include <Adaptor3d_CurveOnSurface.hxx>
#include <BRepAdaptor_Curve.hxx>
#include <BRepLib_ValidateEdge.hxx>
#include <BRepBndLib.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <Geom_Curve.hxx>
#include <Geom_ElementarySurface.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_Pnt2d.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "rational_weights.hpp"
#include "shape_names.hpp"
#include "stored_curves.hpp"

namespace hg::geometry {
namespace {

// OCCT bounds an unbounded direction by +-Precision::Infinite() (2e100), a finite number.
bool unbounded(double lo, double hi) {
  return !std::isfinite(lo) || !std::isfinite(hi) || Precision::IsInfinite(lo) || Precision::IsInfinite(hi);
}

// How far p lies from a direction's parameters [lo, hi], in periods (periodic) or spans;
// an unbounded direction's (a cylinder's or cone's length) within `reach` of 0.
bool runsAway(double p, double lo, double hi, bool periodic, double period, double reach) {
  if (periodic) return !(std::abs(p - lo) <= kMaxPeriods * period);  // NaN runs away
  if (unbounded(lo, hi)) return !(std::abs(p) <= reach);
  const double span = std::max(hi - lo, Precision::PConfusion());
  return !(p >= lo - kMaxPeriods * span && p <= hi + kMaxPeriods * span);
}

const std::string kTimes = std::to_string(static_cast<int>(kMaxPeriods));

// The curve an edge's parameters run along (Trimmed: Geom_TrimmedCurve or Geom2d_TrimmedCurve).
// A trimmed curve evaluates its basis curve at any parameter, inside its trim or not, yet is
// never periodic itself (Geom_TrimmedCurve says so even of a half circle): an edge on a
// trimmed circle goes round the circle (fuzz_brep: a half cylinder's top edge on
// [0.1, 3.4e13], whose mesh took 6 GB in 10 s).
template <class Trimmed, class Curve>
opencascade::handle<Curve> untrimmed(opencascade::handle<Curve> curve) {
  while (const auto trimmed = opencascade::handle<Trimmed>::DownCast(curve)) curve = trimmed->BasisCurve();
  return curve;
}

// How many times [first, last] goes round a periodic curve; 0 on one that is not.
template <class Curve>
double turns(const Curve& curve, double first, double last) {
  return curve->IsPeriodic() ? std::abs(last - first) / curve->Period() : 0;
}

std::string goesRound(double turns, const std::string& what) {
  char text[96];
  std::snprintf(text, sizeof text, " goes %.3g times round its curve%s (an edge goes round once at most)", turns,
                what.c_str());
  return text;
}

// An edge that goes round its 3D curve, or a curve stored on one of its faces, more than
// kMaxEdgeTurns times, in words, or "". Only stored curves on faces are read: OCCT makes up
// a missing one on a plane by a projection that can itself loop (fuzz_brep: a half
// cylinder's top edge on [0, 1.4e13] along a circle on its plane top face, on which
// BRepCheck's wire self-intersection never ended).
std::string edgeGoesRound(const TopoDS_Shape& shape, const TopoDS_Edge& edge) {
  double first = 0, last = 0;
  const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, first, last);
  if (curve.IsNull()) return subShapeName(shape, edge) + " has no 3D curve";
  if (const double n = turns(untrimmed<Geom_TrimmedCurve>(curve), first, last); !(n <= kMaxEdgeTurns))
    return subShapeName(shape, edge) + goesRound(n, "");
  for (const StoredCurveOnFace& stored : storedCurvesOnFaces(edge)) {
    const double n = turns(untrimmed<Geom2d_TrimmedCurve>(stored.curve), stored.first, stored.last);
    if (!(n <= kMaxEdgeTurns)) return subShapeName(shape, edge) + goesRound(n, " on " + faceOf(shape, edge, stored));
  }
  return "";
}

// An edge without a vertex at an end or both, in words, or "". OCCT takes such an edge as
// unbounded: BRepBuilderAPI_Copy, as the crossing search copies the part, gave a parabola
// edge [-2e100, 2e100], and BRepMesh tessellated it for good (fuzz_brep: a vertex record
// lost to a stray byte). Checked last: the damage the other checks name is more telling.
std::string edgeWithoutEnds(const TopoDS_Shape& shape) {
  for (TopExp_Explorer e(shape, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    if (TopExp::FirstVertex(edge).IsNull() || TopExp::LastVertex(edge).IsNull())
      return subShapeName(shape, edge) + " has no vertex at one end or both";
  }
  return "";
}

bool isPlane(const TopoDS_Face& face) {
  TopLoc_Location location;
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(face, location);
  return !surface.IsNull() && GeomAdaptor_Surface(surface).GetType() == GeomAbs_Plane;
}

// The diagonal of the box around the shape's vertices: a scale that no damaged curve
// or surface can stretch.
double vertexSpan(const TopoDS_Shape& shape) {
  gp_XYZ lo(HUGE_VAL, HUGE_VAL, HUGE_VAL), hi(-HUGE_VAL, -HUGE_VAL, -HUGE_VAL);
  for (TopExp_Explorer v(shape, TopAbs_VERTEX); v.More(); v.Next()) {
    const gp_XYZ p = BRep_Tool::Pnt(TopoDS::Vertex(v.Current())).XYZ();
    for (int k = 1; k <= 3; ++k) {
      lo.SetCoord(k, std::min(lo.Coord(k), p.Coord(k)));
      hi.SetCoord(k, std::max(hi.Coord(k), p.Coord(k)));
    }
  }
  return lo.X() <= hi.X() ? (hi - lo).Modulus() : 0.0;
}

// How far the shape's farthest vertex lies from the origin.
double farthestVertex(const TopoDS_Shape& shape) {
  double farthest = 0;
  for (TopExp_Explorer v(shape, TopAbs_VERTEX); v.More(); v.Next())
    farthest = std::max(farthest, BRep_Tool::Pnt(TopoDS::Vertex(v.Current())).XYZ().Modulus());
  return farthest;
}

}  // namespace

bool CurveOnFace::emptyRange() const {
  return !(std::isfinite(first) && std::isfinite(last) && last - first > Precision::PConfusion());
}

std::string CurveOnFace::runaway(double partReach) const {
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
  if (surface.IsNull() || emptyRange()) return "";
  // A length along an elementary surface is measured from its location.
  const Handle(Geom_ElementarySurface) elementary = Handle(Geom_ElementarySurface)::DownCast(surface);
  const double reach = partReach + (elementary.IsNull() ? 0.0 : elementary->Location().XYZ().Modulus());
  const bool uPeriodic = surface->IsUPeriodic(), vPeriodic = surface->IsVPeriodic();
  const double uPeriod = uPeriodic ? surface->UPeriod() : 0, vPeriod = vPeriodic ? surface->VPeriod() : 0;
  double u1 = 0, u2 = 0, v1 = 0, v2 = 0;
  surface->Bounds(u1, u2, v1, v2);
  constexpr int kSamples = 8;
  for (int i = 0; i <= kSamples; ++i) {
    const gp_Pnt2d uv = curve->Value(first + (last - first) * i / kSamples);
    for (const auto& [p, lo, hi, periodic, period] : {std::tuple{uv.X(), u1, u2, uPeriodic, uPeriod},
                                                       std::tuple{uv.Y(), v1, v2, vPeriodic, vPeriod}}) {
      if (!runsAway(p, lo, hi, periodic, period, reach)) continue;
      if (periodic) return "runs more than " + kTimes + " times round";
      return unbounded(lo, hi) ? "runs " + kTimes + " times the part's size off" : "runs " + kTimes + " times its size off";
    }
  }
  return "";
}

// The diagonal of the box around the 3D curves of the face's edges that are not degenerate.
double edgesSpan(const TopoDS_Face& face) {
  Bnd_Box box;
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next())
    if (!BRep_Tool::Degenerated(TopoDS::Edge(e.Current()))) BRepBndLib::Add(e.Current(), box, false);
  return box.IsVoid() ? HUGE_VAL : std::sqrt(box.SquareExtent());
}

std::string CurveOnFace::falseDegenerate(double partSize) const {
  if (!BRep_Tool::Degenerated(edge) || emptyRange()) return "";
  // The face's own edges too: one damaged vertex 196 m off stretched a 21 mm cone's part
  // size, and its 176 mm apex circle passed (fuzz_brep).
  partSize = std::min(partSize, edgesSpan(face));
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
  if (surface.IsNull()) return "";
  constexpr int kSamples = 8;
  const gp_Pnt2d uv0 = curve->Value(first);
  const gp_Pnt p0 = surface->Value(uv0.X(), uv0.Y());
  double spread = 0;
  for (int i = 1; i <= kSamples; ++i) {
    const gp_Pnt2d uv = curve->Value(first + (last - first) * i / kSamples);
    spread = std::max(spread, p0.Distance(surface->Value(uv.X(), uv.Y())));
  }
  // Not widened by the edge's tolerance: BRepMesh splits the edge's curve on the face until
  // its points lie within the crossing search's deflection (1% of the part) of the one 3D
  // point, which a wider spread never does (a 1 mm tolerance let an apex circle of 0.4 mm
  // on a 21 mm cone through, and the split never ended; fuzz_brep).
  if (!(spread <= kMaxDegenerateSpread * partSize)) {
    char text[96];
    std::snprintf(text, sizeof text, "is marked degenerate yet spans %.3g (the part's size %.3g)", spread, partSize);
    return text;
  }
  return "";
}

std::string CurveOnFace::seamOnItself() const {
  if (!BRep_Tool::IsClosed(edge, face) || emptyRange()) return "";
  double first2 = 0, last2 = 0;
  const Handle(Geom2d_Curve) other =
      BRep_Tool::CurveOnSurface(TopoDS::Edge(edge.Reversed()), face, first2, last2);
  if (other.IsNull() || other == curve) return other.IsNull() ? "" : "is a seam whose two curves are one";
  // Both curves run over the edge's one range (OCCT keeps a seam's curves on it).
  constexpr int kSamples = 4;
  for (int i = 0; i <= kSamples; ++i) {
    const double t = first + (last - first) * i / kSamples;
    if (!(curve->Value(t).Distance(other->Value(t)) <= Precision::PConfusion())) return "";
  }
  return "is a seam whose two curves coincide";
}

double curveOnFaceDeviation(const TopoDS_Edge& edge, const TopoDS_Face& face) {
  try {
    if (BRep_Tool::Degenerated(edge) || !BRep_Tool::IsGeometric(edge)) return 0;
    double first = 0, last = 0;
    const Handle(Geom2d_Curve) curve = BRep_Tool::CurveOnSurface(edge, face, first, last);
    if (curve.IsNull()) return 0;  // no curve on this face: nothing to compare
    // Both placed in the shape, as BRepCheck compares them: the 3D curve by the edge's
    // location, the surface by the face's (BRep_Tool::Surface). BRepAdaptor_Curve's
    // CurveOnSurface() is in the surface's own frame, its placement kept apart: compared with
    // the placed 3D curve, every edge of a located face strayed by the placement (a valid
    // plate's holes, 14 and 81 mm).
    const Handle(Adaptor3d_Curve) reference = new BRepAdaptor_Curve(edge);
    const Handle(Adaptor3d_CurveOnSurface) other = new Adaptor3d_CurveOnSurface(
        new Geom2dAdaptor_Curve(curve, first, last), new GeomAdaptor_Surface(BRep_Tool::Surface(face)));
    BRepLib_ValidateEdge validate(reference, other, BRep_Tool::SameParameter(edge));
    validate.Process();
    return validate.IsDone() ? validate.GetMaxDistance() : HUGE_VAL;
  } catch (const Standard_Failure&) {
    return HUGE_VAL;
  }
}

std::vector<FaceOffItsEdges> curvedFacesOffTheirEdges(const TopoDS_Shape& shape, double limit) {
  TopTools_IndexedMapOfShape faces, edges;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  TopExp::MapShapes(shape, TopAbs_EDGE, edges);
  std::vector<FaceOffItsEdges> off;
  for (int f = 1; f <= faces.Extent(); ++f) {
    const TopoDS_Face& face = TopoDS::Face(faces(f));
    if (isPlane(face)) continue;
    FaceOffItsEdges worst{f, 0, 0};
    for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) {
      const double d = curveOnFaceDeviation(TopoDS::Edge(e.Current()), face);
      if (!(d <= worst.distance)) worst = {f, edges.FindIndex(e.Current()), d};
    }
    if (!(worst.distance <= limit)) off.push_back(worst);
  }
  return off;
}

std::string firstCurveOnFace(const TopoDS_Shape& shape, const std::function<std::string(const CurveOnFace&)>& why) {
  for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next()) {
    // A plane is neither periodic nor bounded, so neither check applies; and OCCT computes a
    // curve on a plane that has none stored, by a projection that can itself loop.
    if (isPlane(TopoDS::Face(f.Current()))) continue;
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

std::string damagedGeometry(const TopoDS_Shape& shape) {
  if (std::string weights = weightsTooFarApart(shape); !weights.empty()) return weights;
  for (TopExp_Explorer e(shape, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    try {
      if (BRep_Tool::Degenerated(edge)) continue;  // a pole or apex: no 3D curve (falseDegenerate below)
      if (std::string round = edgeGoesRound(shape, edge); !round.empty()) return round;
    } catch (const Standard_Failure&) {
      return subShapeName(shape, edge) + "'s curve cannot be evaluated";
    }
  }
  const double size = vertexSpan(shape);
  const double reach = kMaxPeriods * (size + farthestVertex(shape));
  if (std::string runaway = firstCurveOnFace(shape, [reach](const CurveOnFace& c) { return c.runaway(reach); });
      !runaway.empty())
    return runaway;
  if (std::string seam = firstCurveOnFace(shape, [](const CurveOnFace& c) { return c.seamOnItself(); }); !seam.empty())
    return seam;
  if (std::string apex = firstCurveOnFace(shape, [size](const CurveOnFace& c) { return c.falseDegenerate(size); });
      !apex.empty())
    return apex;
  return edgeWithoutEnds(shape);
}

}  // namespace hg::geometry
