#include "hapticgrasp/geometry/backends.hpp"

#include <string>

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

}  // namespace

PenetrationModelPtr makePenetration(PartModelPtr part, Backend backend, double setting_m) {
  if (!part) throw GeometryError("no part to answer");
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

std::string autoBackendReason(const PartModel& part, std::string_view answeredBy) {
  const std::string& reason = part.backendChoice().reason;
  if (answeredBy == toString(Backend::Analytic))
    return std::string("analytic: a recognised ") + toString(part.primitive().kind) + ", in closed form; " + reason;
  return reason;
}

}  // namespace hg::geometry
