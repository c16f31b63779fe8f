#include "hapticgrasp/geometry/units.hpp"

#include <string>

#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::geometry {

LengthUnit parseLengthUnit(std::string_view text) {
  if (text == "m") return LengthUnit::Metre;
  if (text == "mm") return LengthUnit::Millimetre;
  throw GeometryError("unknown length unit '" + std::string(text) + "' (use m or mm)");
}

}  // namespace hg::geometry
