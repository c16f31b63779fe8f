#pragma once
// Whether a (u, v) point lies inside a trimmed face: OCCT's BRepTopAdaptor_FClass2d
// answers from a polygon and allocates on every call, so this is written by hand. It is
// exact and allocation-free: each boundary pcurve is cut, once, into pieces along which v
// is monotone; a query casts a ray towards +u and counts the pieces it crosses, solving
// v(t) = v0 by bisection only for the pieces whose box it cannot decide from. Gaps
// between consecutive pcurves (within tolerance, so valid) are bridged by segments.
#include <Geom2d_Curve.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Wire.hxx>

#include <vector>

namespace hg::geometry::exact {

class UvDomain {
 public:
  explicit UvDomain(const TopoDS_Face& face);
  bool contains(double u, double v) const noexcept;
  // Whether the rectangle lies wholly outside the face: no boundary curve comes near it
  // and its centre is outside.
  bool rectOutside(double u0, double u1, double v0, double v1) const noexcept;
  std::size_t memoryBytes() const noexcept;

 private:
  struct Piece {
    const Geom2d_Curve* curve;  // owned by curves_
    double t0, t1;              // v(t) is monotone on [t0, t1]
    double vLow, vHigh;         // v over the piece
    double uLow, uHigh;         // u over the piece (with a margin)
    bool increasing;            // v(t0) < v(t1)  (kept for clarity of the box; the root needs no orientation)
  };
  bool crosses(const Piece& piece, double u, double v) const noexcept;
  void addWire(const TopoDS_Wire& wire, const TopoDS_Face& face);
  void addCurve(const Handle(Geom2d_Curve)& curve, double first, double last);
  void addPiece(const Geom2d_Curve* curve, double t0, double t1);
  void buildBins();

  std::vector<Handle(Geom2d_Curve)> curves_;
  std::vector<Piece> pieces_;
  struct Box {
    double u0, u1, v0, v1;
  };
  std::vector<Box> boundaryBoxes_;  // every piece's box, constant-v pieces included
  // The pieces overlapping each band of v, so that a query looks at few of them.
  double vMin_ = 0, vMax_ = 0;
  std::vector<std::vector<int>> bins_;
};

}  // namespace hg::geometry::exact
