#pragma once
#include <stdexcept>

namespace hg::geometry {

// A part that cannot be used, with a message naming the problem (empty file, not a solid,
// open shell, self-intersection...). Thrown only while building models, never by a query.
class GeometryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hg::geometry
