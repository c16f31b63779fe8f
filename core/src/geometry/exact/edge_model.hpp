#pragma once
// One B-rep edge prepared for closest-point queries, and the outward direction beside it
// (the sum of its two faces' normals), which decides the sign of a point whose closest
// feature is the edge.
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <GeomAbs_CurveType.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Circ.hxx>
#include <gp_Lin.hxx>

#include <vector>

#include "face_model.hpp"

namespace hg::geometry::exact {

struct EdgeFoot {
  double t = 0;
  gp_Pnt point;
  double distance = 0;
};

class EdgeModel {
 public:
  // `faces`: the (one or two) faces bounding the edge, as oriented in the solid, with their
  // 0-based indices into the FaceModel array.
  EdgeModel(const TopoDS_Edge& edge, const std::vector<std::pair<TopoDS_Face, int>>& faces);

  // A seam or a degenerated edge is never the closest feature: its face answers for it.
  bool usable() const { return usable_; }
  // The closest interior point of the edge; false when it is an end (a vertex answers),
  // or when it cannot beat `bound`. t is left where the search ended (next warm start).
  bool project(const gp_Pnt& x, bool warm, double& t, double bound, EdgeFoot& foot) const noexcept;
  // The sum of the adjacent faces' outward normals at parameter t.
  gp_Vec pseudoNormal(double t, const std::vector<FaceModel>& faces) const noexcept;
  std::size_t memoryBytes() const noexcept { return sizeof(*this) + seeds_.capacity() * sizeof(seeds_[0]); }

 private:
  bool newton(const gp_Pnt& x, double& t) const noexcept;
  double fit(double t) const noexcept;

  bool usable_ = false;
  Handle(Geom_Curve) curve_;
  GeomAbs_CurveType type_ = GeomAbs_OtherCurve;
  gp_Lin line_;
  gp_Circ circle_;
  double t0_ = 0, t1_ = 0, period_ = 0;
  struct Side {
    int face = -1;
    Handle(Geom2d_Curve) pcurve;
  };
  Side sides_[2];
  int sideCount_ = 0;
  std::vector<std::pair<double, gp_Pnt>> seeds_;  // freeform curves only
};

}  // namespace hg::geometry::exact
