#include "hapticgrasp/geometry/display_shape.hpp"

#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BinTools.hxx>
#include <Bnd_Box.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS_Shape.hxx>

#include <cmath>
#include <sstream>
#include <string>

#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "meshing_limits.hpp"

namespace hg::geometry {
namespace {

TopoDS_Shape readBinary(std::string_view bytes) {
  TopoDS_Shape shape;
  try {
    OCC_CATCH_SIGNALS  // a fault in the reader is a bad file (occt_faults.hpp)
    std::istringstream in(std::string(bytes), std::ios::binary);
    BinTools::Read(shape, in);
  } catch (const Standard_Failure& e) {
    const std::string why = e.GetMessageString();
    throw GeometryError("is not a binary BREP" + (why.empty() ? "" : " (" + why + ")"));
  }
  if (shape.IsNull()) throw GeometryError("is not a binary BREP");
  return shape;
}

// As FreeCAD's Part view provider meshes it for display; the triangles are dropped after.
void meshForDisplay(const TopoDS_Shape& shape, const DisplayCheck& check) {
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  if (box.IsVoid()) throw GeometryError("cannot be shown: it has no extent");
  double x0, y0, z0, x1, y1, z1;
  box.Get(x0, y0, z0, x1, y1, z1);
  const double deflection = ((x1 - x0) + (y1 - y0) + (z1 - z0)) / 300.0 * check.deviation;
  if (!(deflection > 0) || !std::isfinite(deflection)) throw GeometryError("cannot be shown: it has no finite extent");
  const MeshingParameters parameters{deflection, check.angle_deg / 180.0 * M_PI};
  // The view provider would mesh such a face for minutes and gigabytes (meshing_limits.hpp).
  if (!surfaceGrids(shape, parameters).beyondTheLimit.empty())
    throw GeometryError("cannot be shown: a face would need more than " +
                        std::to_string(static_cast<long>(kMaxSurfaceGridNodes)) + " nodes in its display mesh");
  try {
    OCC_CATCH_SIGNALS
    BRepMesh_IncrementalMesh mesh(shape, deflection, false, parameters.angle, false);
    if (!mesh.IsDone()) throw GeometryError("cannot be shown: its display mesh failed");
  } catch (const Standard_Failure& e) {
    throw GeometryError(std::string("cannot be shown: its display mesh failed (") + e.GetMessageString() + ")");
  }
  BRepTools::Clean(shape);
}

}  // namespace

std::string displayableBrepText(std::string_view binaryBrep, LengthUnit unit, const std::string& name,
                                const DisplayCheck& check) {
  const TopoDS_Shape shape = readBinary(binaryBrep);
  try {
    PartModel::fromShape(shape, unit, name);
  } catch (const GeometryError& e) {
    throw GeometryError(std::string("is refused: ") + e.what());
  }
  if (check.mesh) meshForDisplay(shape, check);
  std::ostringstream out;
  BRepTools::Write(shape, out, /*theWithTriangles=*/false, /*theWithNormals=*/false, TopTools_FormatVersion_CURRENT);
  return std::move(out).str();
}

}  // namespace hg::geometry
