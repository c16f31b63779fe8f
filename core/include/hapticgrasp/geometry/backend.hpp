#pragma once
// The penetration back ends by name, and the one a part's load chose for it (with why):
// a part model records its choice, the back-end factory (backends.hpp) honours it.
#include <string>
#include <string_view>

namespace hg::geometry {

enum class Backend { Reference, Exact, Mesh, Field, Analytic, Auto };
std::string_view toString(Backend backend);
Backend parseBackend(std::string_view name);  // throws GeometryError

// The back end that answers a part when none is asked for, and why, in one line
// ("exact: valid B-rep", "mesh 0.01 mm: faces 27 and 31 cross (not healable); ...").
struct BackendChoice {
  Backend backend = Backend::Exact;
  std::string reason;
  // The part keeps a defect no fix removed (the reason names it): its surface may cross
  // itself, so what it encloses is told by its winding number, not by the normals of the
  // face nearest a point (which a face passing through the solid turns the wrong way).
  bool surfaceMayCross = false;
};

}  // namespace hg::geometry
