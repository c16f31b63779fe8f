#include "hapticgrasp/geometry/backends.hpp"

#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>

#include <string>

#include "hapticgrasp/geometry/occt_faults.hpp"

namespace hg::geometry {

#ifndef HG_WITH_EMBREE
PenetrationModelPtr makeMeshPenetration(PartModelPtr, double, MeshSign) {
  throw GeometryError("the mesh back end was left out of this build (HG_WITH_EMBREE=OFF)");
}
#endif
#ifndef HG_WITH_OPENVDB
PenetrationModelPtr makeFieldPenetration(PartModelPtr, double) {
  throw GeometryError("the field back end was left out of this build (HG_WITH_OPENVDB=OFF)");
}
#endif

namespace {

// Pseudo-normals sign a sound mesh exactly and cost nothing; a surface that crosses itself
// turns some of them against what it encloses, and only its winding number tells.
PenetrationModelPtr meshFor(PartModelPtr part, double setting_m) {
  const MeshSign sign = part->backendChoice().surfaceMayCross ? MeshSign::WindingNumber : MeshSign::PseudoNormal;
  return makeMeshPenetration(std::move(part), setting_m > 0 ? setting_m : kDefaultDeflection_m, sign);
}

PenetrationModelPtr build(PartModelPtr part, Backend backend, double setting_m) {
  switch (backend) {
    case Backend::Reference: return makeReferencePenetration(std::move(part));
    case Backend::Exact: return makeExactPenetration(std::move(part));
    case Backend::Mesh: return meshFor(std::move(part), setting_m);
    case Backend::Field: return makeFieldPenetration(std::move(part), setting_m > 0 ? setting_m : kDefaultVoxel_m);
    case Backend::Analytic: return makeAnalyticPenetration(std::move(part));
    default: break;
  }
  // Auto: what the part's load chose. A defect the exact back end would answer wrongly
  // goes to the robust one it named.
  const Backend chosen = part->backendChoice().backend;
  if (chosen == Backend::Mesh) return meshFor(std::move(part), setting_m);
  if (chosen == Backend::Field) return makeFieldPenetration(std::move(part), setting_m > 0 ? setting_m : kDefaultVoxel_m);
  if (part->primitive().kind != Primitive::Kind::None) {
    try {
      return makeAnalyticPenetration(part);
    } catch (const GeometryError&) {
      // A primitive whose topology the closed form cannot name (a split rim, many
      // edges): the exact back end answers it as well, only slower.
    }
  }
  return makeExactPenetration(std::move(part));
}

}  // namespace

// OCCT's failures while building (a damaged part the load let through to a robust back end:
// BRepAdaptor_Curve's "No geometry" in the mesh back end's face fill, found by building the
// back end of each brep fuzz input) become one GeometryError, as in the part's load; a
// fault under OCCT's handlers too (occt_faults.hpp). Without this, the command line said
// only "OpenCASCADE failed" and the workbench "unknown error while building the model".
PenetrationModelPtr makePenetration(PartModelPtr part, Backend backend, double setting_m) {
  if (!part) throw GeometryError("no part to answer");
  const FaultStack faultStack;
  try {
    OCC_CATCH_SIGNALS
    return build(std::move(part), backend, setting_m);
  } catch (const Standard_Failure& e) {
    throw GeometryError(std::string("OpenCASCADE failed building the back end: ") + e.GetMessageString());
  }
}

std::string autoBackendReason(const PartModel& part, std::string_view answeredBy) {
  const std::string& reason = part.backendChoice().reason;
  if (answeredBy == toString(Backend::Analytic))
    return std::string("analytic: a recognised ") + toString(part.primitive().kind) + ", in closed form; " + reason;
  return reason;
}

}  // namespace hg::geometry
