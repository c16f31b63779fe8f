#pragma once
// One B-rep edge prepared for closest-point queries, and the outward direction beside it
// (the sum of its two faces' normals), which decides the sign of a point whose closest
// feature is the edge. Lines and circles are answered in closed form; every other curve
// is cut into pieces (curve_pieces.hpp), searched by Newton where x is clear of their focal
// points and exhaustively elsewhere.
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <GeomAbs_CurveType.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Circ.hxx>
#include <gp_Lin.hxx>

#include <vector>

#include "curve_pieces.hpp"
#include "face_model.hpp"

namespace hg::geometry::exact {

struct EdgeFoot {
  double t = 0;
  gp_Pnt point;
  double distance = 0;
};

struct EdgeSearch {
  bool found = false;   // an interior foot closer than the bound
  bool certain = true;  // false: a closer foot may hide on the piece (x near its focal points)
};

class EdgeModel {
 public:
  // `faces`: the (one or two) faces bounding the edge, as oriented in the solid, with their
  // 0-based indices into the FaceModel array.
  EdgeModel(const TopoDS_Edge& edge, const std::vector<std::pair<TopoDS_Face, int>>& faces,
            double characteristicLength);

  // A seam or a degenerated edge is never the closest feature: its face answers for it.
  bool usable() const { return usable_; }
  // Freeform curves are searched piece by piece (each a leaf of the part's BVH); lines and
  // circles as a whole (piece -1).
  const std::vector<CurvePiece>& pieces() const { return pieces_; }

  // The closest interior point of the edge (or of one piece of it) to x, if closer than
  // `bound`; the ends belong to the vertices. t: warm start in when `warm`, where the
  // search ended out.
  EdgeSearch project(const gp_Pnt& x, int piece, bool warm, double& t, double bound, EdgeFoot& foot) const noexcept;
  // The exhaustive search of one piece (the fallback where `project` was not certain).
  // `budget`: the surface or curve evaluations it may still spend, less what it spent.
  EdgeSearch exhaust(const gp_Pnt& x, int piece, double bound, EdgeFoot& foot, int& budget) const noexcept;
  // Whether a Newton search on the edge (or piece) is certain when only feet closer than
  // `best` matter.
  bool certainFor(int piece, double best) const noexcept { return piece < 0 || pieces_[piece].clearOfFocus(best); }

  // The sum of the adjacent faces' outward normals at parameter t.
  gp_Vec pseudoNormal(double t, const std::vector<FaceModel>& faces) const noexcept;
  std::size_t memoryBytes() const noexcept { return sizeof(*this) + pieces_.capacity() * sizeof(CurvePiece); }

  // The curve at t, wrapped across a closed edge's seam.
  void d2(double t, gp_Pnt& p, gp_Vec& d1, gp_Vec& d2) const noexcept { curve_->D2(fit(t), p, d1, d2); }

 private:
  double fit(double t) const noexcept;
  bool accept(const gp_Pnt& x, double t, double bound, EdgeFoot& foot) const noexcept;
  EdgeSearch projectPiece(const gp_Pnt& x, int piece, bool warm, double& t, double bound,
                          EdgeFoot& foot) const noexcept;

  bool usable_ = false;
  Handle(Geom_Curve) curve_;
  GeomAbs_CurveType type_ = GeomAbs_OtherCurve;
  gp_Lin line_;
  gp_Circ circle_;
  double t0_ = 0, t1_ = 0, period_ = 0;
  double tolerance_ = 0, accuracy_ = 0;
  struct Side {
    int face = -1;
    Handle(Geom2d_Curve) pcurve;
  };
  Side sides_[2];
  int sideCount_ = 0;
  std::vector<CurvePiece> pieces_;  // freeform curves only
};

}  // namespace hg::geometry::exact
