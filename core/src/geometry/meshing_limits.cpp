#include "meshing_limits.hpp"

#include <BRepMesh_Context.hxx>
#include <GCPnts_TangentialDeflection.hxx>
#include <IMeshData_Edge.hxx>
#include <IMeshData_Face.hxx>
#include <IMeshData_Model.hxx>
#include <IMeshData_PCurve.hxx>
#include <IMeshData_Wire.hxx>
#include <Precision.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hg::geometry {

namespace {

constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// The parameter range BRepMesh's range splitters take: over the points of the discretized
// pcurves of the face's first `wires` wires.
struct UvSpan {
  double u0 = kUnbounded, u1 = -kUnbounded, v0 = kUnbounded, v1 = -kUnbounded;
  double du() const { return u1 - u0; }
  double dv() const { return v1 - v0; }
  bool empty() const { return !(u1 >= u0) || !(v1 >= v0); }
};

UvSpan pointSpan(const IMeshData::IFaceHandle& face, int wires) {
  UvSpan span;
  for (int w = 0; w < std::min(wires, face->WiresNb()); ++w) {
    const IMeshData::IWireHandle& wire = face->GetWire(w);
    for (int e = 0; e < wire->EdgesNb(); ++e) {
      const IMeshData::IPCurveHandle& pcurve = wire->GetEdge(e)->GetPCurve(face.get(), wire->GetEdgeOrientation(e));
      for (int k = 0; k < pcurve->ParametersNb(); ++k) {
        const gp_Pnt2d& p = pcurve->GetPoint(k);
        span.u0 = std::min(span.u0, p.X()), span.u1 = std::max(span.u1, p.X());
        span.v0 = std::min(span.v0, p.Y()), span.v1 = std::max(span.v1, p.Y());
      }
    }
  }
  return span;
}

// Each splitter below steps as its namesake in OCCT 7.6 does, in doubles where it truncates to
// int: a NaN or a count beyond int, which BRepMesh turns into a step of ~1e-8, stays visible.
struct GridInput {
  UvSpan span;
  double deflection;  // the face's, as BRepMesh set it from its edges
  const IMeshTools_Parameters& parameters;

  double arcStep(double radius) const {
    return GCPnts_TangentialDeflection::ArcAngularStep(radius, deflection, parameters.Angle, parameters.MinSize);
  }
};

// BRepMesh_ConeRangeSplitter::GetSplitSteps: U by the arc step at the wider end, V so that
// cells are square there. Its V step also spaces the points BRepMesh_ModelPreProcessor adds
// along a cone's seam, over the first wire's span.
double coneNodes(const gp_Cone& cone, const GridInput& in) {
  const double s = std::sin(cone.SemiAngle());
  const double radius = std::max(std::abs(cone.RefRadius() + in.span.v0 * s), std::abs(cone.RefRadius() + in.span.v1 * s));
  const double nbU = std::floor(in.span.du() / in.arcStep(radius));
  const double nbV = nbU * in.span.dv() / (in.span.du() * radius);  // 0/0 on a span without width
  return (nbU + 1) * (nbV + 1);
}

// BRepMesh_CylinderRangeSplitter: U by the arc step, V as square cells, at most 100 per U step.
double cylinderNodes(const gp_Cylinder& cylinder, const GridInput& in) {
  const double radius = cylinder.Radius();
  if (!(in.span.du() * radius > in.deflection)) return 1;
  const double nbU = std::floor(in.span.du() / in.arcStep(radius));
  const double nbV = std::min(nbU * in.span.dv() / (in.span.du() * radius), 100 * nbU);
  return (nbU + 1) * (nbV + 1);
}

// BRepMesh_SphereRangeSplitter: both directions by 0.7 of the arc step.
double sphereNodes(const gp_Sphere& sphere, const GridInput& in) {
  const double step = 0.7 * in.arcStep(sphere.Radius());
  return (in.span.du() / step + 1) * (in.span.dv() / step + 1);
}

// BRepMesh_TorusRangeSplitter: V by the minor circle's arc step, U by the outer equator's,
// U cells at most five times as long as V's.
double torusNodes(const gp_Torus& torus, const GridInput& in) {
  const double minor = torus.MinorRadius(), major = torus.MajorRadius();
  const double dv = in.arcStep(minor);
  double du = in.arcStep(major + minor);
  du *= std::min(dv, du) / std::hypot(du, dv);
  const double nbV = std::max(std::floor(in.span.dv() / dv), 2.0);
  const double nbU = std::max({std::floor(in.span.du() / du), 2.0, nbV * in.span.du() * major / (in.span.dv() * minor) / 5});
  return (nbU + 1) * (nbV + 1);
}

// The nodes the splitter of `face`'s surface lays over `span`; 0 for the surfaces whose
// splitters work from the boundary and the surface's own knots.
double gridNodes(const IMeshData::IFaceHandle& face, const UvSpan& span, const IMeshTools_Parameters& parameters) {
  if (span.empty()) return 0;  // no points: BRepMesh lays no grid
  const BRepAdaptor_Surface& surface = *face->GetSurface();
  const GridInput in{span, face->GetDeflection(), parameters};
  double nodes = 0;
  switch (surface.GetType()) {
    case GeomAbs_Cone: nodes = coneNodes(surface.Cone(), in); break;
    case GeomAbs_Cylinder: nodes = cylinderNodes(surface.Cylinder(), in); break;
    case GeomAbs_Sphere: nodes = sphereNodes(surface.Sphere(), in); break;
    case GeomAbs_Torus: nodes = torusNodes(surface.Torus(), in); break;
    default: return 0;
  }
  return std::isfinite(nodes) && nodes >= 0 ? nodes : kUnbounded;
}

// The larger of the grids the face's mesher (all wires) and, on a cone, the seam amplifier
// (the first wire) would lay out.
double faceGridNodes(const IMeshData::IFaceHandle& face, const IMeshTools_Parameters& parameters) {
  double nodes = gridNodes(face, pointSpan(face, face->WiresNb()), parameters);
  if (face->GetSurface()->GetType() == GeomAbs_Cone) nodes = std::max(nodes, gridNodes(face, pointSpan(face, 1), parameters));
  return nodes;
}

// Fails the faces of the context's model whose grid is beyond kMaxSurfaceGridNodes (BRepMesh's
// face discretization skips failed faces) and records them.
void failFacesBeyondTheLimit(const IMeshTools_Context& context, SurfaceGrids& grids) {
  const Handle(IMeshData_Model)& model = context.GetModel();
  for (int i = 0; i < model->FacesNb(); ++i) {
    const IMeshData::IFaceHandle& face = model->GetFace(i);
    const double nodes = faceGridNodes(face, context.GetParameters());
    if (nodes > kMaxSurfaceGridNodes) {
      face->SetStatus(IMeshData_Failure);
      grids.beyondTheLimit.push_back(face->GetFace());
    } else {
      grids.largest = std::max(grids.largest, nodes);
    }
  }
}

// BRepMesh's own steps, with the faces beyond the limit failed before the pre-processor.
// The seam amplifier in BRepMesh_ModelPreProcessor does not look at a face's status: with
// such a cone in the model the pre-processor is skipped. That loses the other cones' extra
// seam points (a damaged shape's cones get a coarser seam) and the reuse or cleaning of
// earlier triangulations (the shapes meshed here are copies that carry none).
class GridLimitedContext final : public BRepMesh_Context {
 public:
  Standard_Boolean PreProcessModel() override {
    failFacesBeyondTheLimit(*this, grids_);
    for (const TopoDS_Face& face : grids_.beyondTheLimit)
      if (BRepAdaptor_Surface(face, false).GetType() == GeomAbs_Cone) return Standard_True;
    return BRepMesh_Context::PreProcessModel();
  }
  const SurfaceGrids& grids() const { return grids_; }

 private:
  SurfaceGrids grids_;
};

// IMeshTools_Parameters as BRepMesh_IncrementalMesh completes them.
IMeshTools_Parameters meshParameters(const MeshingParameters& p) {
  IMeshTools_Parameters parameters;
  parameters.Deflection = p.deflection;
  parameters.DeflectionInterior = p.deflection;
  parameters.Angle = p.angle;
  parameters.AngleInterior = 2 * p.angle;
  parameters.MinSize = p.minSize();
  parameters.InParallel = false;
  return parameters;
}

}  // namespace

double MeshingParameters::minSize() const {
  return std::max(IMeshTools_Parameters::RelMinSize() * deflection, Precision::Confusion());
}

SurfaceGrids surfaceGrids(const TopoDS_Shape& shape, const MeshingParameters& parameters) {
  const Handle(GridLimitedContext) context = new GridLimitedContext;
  context->SetShape(shape);
  context->ChangeParameters() = meshParameters(parameters);
  SurfaceGrids grids;
  try {
    OCC_CATCH_SIGNALS
    if (context->BuildModel() && context->DiscretizeEdges() && context->HealModel())
      failFacesBeyondTheLimit(*context, grids);
  } catch (const Standard_Failure&) {
    // BRepMesh itself fails on such a shape, before laying out any grid.
  }
  return grids;
}

MeshedFaces meshWithin(const TopoDS_Shape& shape, const MeshingParameters& parameters,
                       const Handle(Message_ProgressIndicator)& limit) {
  const Handle(GridLimitedContext) context = new GridLimitedContext;
  BRepMesh_IncrementalMesh mesher;
  mesher.SetShape(shape);
  mesher.ChangeParameters() = meshParameters(parameters);
  mesher.Perform(context, limit.IsNull() ? Message_ProgressRange() : limit->Start());
  return {mesher.IsDone(), context->grids().beyondTheLimit};
}

}  // namespace hg::geometry
