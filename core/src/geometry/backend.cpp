#include "hapticgrasp/geometry/backend.hpp"

#include <string>

#include "hapticgrasp/geometry/geometry_error.hpp"

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

}  // namespace hg::geometry
