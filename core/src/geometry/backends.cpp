#include "hapticgrasp/geometry/backends.hpp"

#include <string>

namespace hg::geometry {

std::string_view toString(Backend backend) {
  switch (backend) {
    case Backend::Reference: return "reference";
    case Backend::Exact: return "exact";
    case Backend::Mesh: return "mesh";
    case Backend::Field: return "field";
    case Backend::Analytic: return "analytic";
    default: return "auto";
  }
}

Backend parseBackend(std::string_view name) {
  for (Backend b : {Backend::Reference, Backend::Exact, Backend::Mesh, Backend::Field, Backend::Analytic, Backend::Auto})
    if (toString(b) == name) return b;
  throw GeometryError("unknown penetration back end '" + std::string(name) +
                      "' (reference, exact, mesh, field, analytic, auto)");
}

#ifndef HG_WITH_EMBREE
PenetrationModelPtr makeMeshPenetration(PartModelPtr, double) {
  throw GeometryError("the mesh back end was left out of this build (HG_WITH_EMBREE=OFF)");
}
#endif
#ifndef HG_WITH_OPENVDB
PenetrationModelPtr makeFieldPenetration(PartModelPtr, double) {
  throw GeometryError("the field back end was left out of this build (HG_WITH_OPENVDB=OFF)");
}
#endif

PenetrationModelPtr makePenetration(PartModelPtr part, Backend backend, double setting_m) {
  switch (backend) {
    case Backend::Reference: return makeReferencePenetration(std::move(part));
    case Backend::Exact: return makeExactPenetration(std::move(part));
    case Backend::Mesh: return makeMeshPenetration(std::move(part), setting_m > 0 ? setting_m : 1e-5);
    case Backend::Field: return makeFieldPenetration(std::move(part), setting_m > 0 ? setting_m : 1e-3);
    case Backend::Analytic: return makeAnalyticPenetration(std::move(part));
    default:
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
}

}  // namespace hg::geometry
