#include "vertex_model.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Vec2d.hxx>

#include <cmath>

namespace hg::geometry::exact {
namespace {

// The tangent of `edge` in the direction the wire travels it, at its start or its end,
// in 3D and in the face's UV plane.
struct Tangents {
  gp_Vec d3;
  gp_Vec2d d2;
  bool ok = false;
};

Tangents travelTangent(const TopoDS_Edge& edge, const TopoDS_Face& face, bool atStart) {
  Tangents t;
  if (BRep_Tool::Degenerated(edge)) return t;
  const bool forward = edge.Orientation() != TopAbs_REVERSED;
  BRepAdaptor_Curve curve(edge);
  const double param = (atStart == forward) ? curve.FirstParameter() : curve.LastParameter();
  gp_Pnt p;
  curve.D1(param, p, t.d3);
  double f, l;
  const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, f, l);
  if (pcurve.IsNull()) return t;
  gp_Pnt2d uv;
  pcurve->D1(param, uv, t.d2);
  if (!forward) {
    t.d3.Reverse();
    t.d2.Reverse();
  }
  t.ok = t.d3.SquareMagnitude() > 0 && t.d2.SquareMagnitude() > 0;
  return t;
}

// The face's interior angle between the edge arriving at the vertex and the edge leaving
// it. The 3D angle between the edges is known up to its reflex twin; which of the two is
// inside the face is decided by classifying a UV point on the bisector (this does not
// depend on how the face's wires happen to be oriented). The face model's exact UV
// domain test does the classifying: OCCT's FClass2d, this close to a boundary, falls back
// to its slow exact classifier (87% of the 1,030-face plate's build).
double interiorAngle(const TopoDS_Edge& in, const TopoDS_Edge& out, const TopoDS_Vertex& v, const TopoDS_Face& face,
                     const FaceModel& model, double probeStep) {
  const Tangents a = travelTangent(in, face, false), b = travelTangent(out, face, true);
  if (!a.ok || !b.ok) return M_PI;
  const gp_Vec back = a.d3.Reversed();
  const double angle = back.Angle(b.d3);  // in [0, pi]
  gp_Vec2d back2 = a.d2.Reversed(), out2 = b.d2;
  back2.Normalize();
  out2.Normalize();
  gp_Vec2d bisector = back2 + out2;
  if (bisector.SquareMagnitude() < 1e-12) bisector = gp_Vec2d(-out2.Y(), out2.X());
  bisector.Normalize();
  const gp_Pnt2d uv = BRep_Tool::Parameters(v, face);
  const gp_Pnt2d probe(uv.X() + probeStep * bisector.X(), uv.Y() + probeStep * bisector.Y());
  return model.contains(probe.X(), probe.Y()) ? angle : 2 * M_PI - angle;
}

// A face's share of the pseudo-normal at a pole: its normals along the degenerated edge
// (just inside the face), each weighted by the angle it turns through there: the
// integral of the normal over the face's fan round the pole.
gp_Vec poleNormal(const TopoDS_Edge& degenerated, const TopoDS_Face& face, const FaceModel& model, double u0,
                  double u1, double v0, double v1) {
  double first, last;
  const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(degenerated, face, first, last);
  if (pcurve.IsNull()) return gp_Vec(0, 0, 0);
  const gp_Pnt2d a = pcurve->Value(first), b = pcurve->Value(last);
  // The fan's angle is the span of the pole's parameter (u round a cone's apex).
  const double span = std::max(std::abs(b.X() - a.X()), std::abs(b.Y() - a.Y()));
  constexpr int kSamples = 32;
  gp_Vec sum(0, 0, 0);
  for (int i = 0; i < kSamples; ++i) {
    const gp_Pnt2d uv = pcurve->Value(first + (last - first) * (i + 0.5) / kSamples);
    const double inU = uv.X() + 1e-6 * (0.5 * (u0 + u1) - uv.X()), inV = uv.Y() + 1e-6 * (0.5 * (v0 + v1) - uv.Y());
    sum += model.normalAt(inU, inV) * (span / kSamples);
  }
  return sum;
}

}  // namespace

std::vector<VertexModel> buildVertexModels(const TopTools_IndexedMapOfShape& vertices,
                                           const TopTools_IndexedMapOfShape& faces,
                                           const std::vector<FaceModel>& faceModels) {
  std::vector<VertexModel> models(vertices.Extent());
  for (int i = 1; i <= vertices.Extent(); ++i) {
    models[i - 1].point = BRep_Tool::Pnt(TopoDS::Vertex(vertices(i)));
    models[i - 1].pseudoNormal = gp_Vec(0, 0, 0);
  }
  for (int f = 1; f <= faces.Extent(); ++f) {
    const TopoDS_Face& face = TopoDS::Face(faces(f));
    double u0, u1, v0, v1;
    BRepTools::UVBounds(face, u0, u1, v0, v1);
    const double probeStep = 1e-5 * std::max(u1 - u0, v1 - v0);
    for (TopExp_Explorer w(face, TopAbs_WIRE); w.More(); w.Next()) {
      std::vector<TopoDS_Edge> edges;
      std::vector<TopoDS_Vertex> starts;  // the vertex each edge starts from
      for (BRepTools_WireExplorer ex(TopoDS::Wire(w.Current()), face); ex.More(); ex.Next()) {
        edges.push_back(ex.Current());
        starts.push_back(ex.CurrentVertex());
      }
      for (std::size_t k = 0; k < edges.size(); ++k) {
        const TopoDS_Edge& in = edges[(k + edges.size() - 1) % edges.size()];
        const int vi = vertices.FindIndex(starts[k]);
        if (vi == 0) continue;
        // A pole (a cone's apex, a sphere's pole) is reached through a degenerated edge:
        // the face fans round it, and adds its normals all round (below), not one.
        if (BRep_Tool::Degenerated(in) || BRep_Tool::Degenerated(edges[k])) continue;
        const double angle = interiorAngle(in, edges[k], starts[k], face, faceModels[f - 1], probeStep);
        const gp_Pnt2d uv = BRep_Tool::Parameters(starts[k], face);
        models[vi - 1].pseudoNormal += angle * faceModels[f - 1].normalAt(uv.X(), uv.Y());
      }
      for (const TopoDS_Edge& e : edges)
        if (BRep_Tool::Degenerated(e)) {
          const int vi = vertices.FindIndex(TopExp::FirstVertex(e));
          if (vi > 0) models[vi - 1].pseudoNormal += poleNormal(e, face, faceModels[f - 1], u0, u1, v0, v1);
        }
    }
  }
  return models;
}

}  // namespace hg::geometry::exact
