#pragma once
// Length units of the files the core reads. The core itself is SI; a part keeps its
// OpenCASCADE shape in the file's unit (OCCT's tolerances are tuned for it) and converts
// every value it hands out to metres, once, at its own boundary.
#include <string_view>

namespace hg::geometry {

enum class LengthUnit { Metre, Millimetre };

constexpr double metresPer(LengthUnit unit) {
  return unit == LengthUnit::Metre ? 1.0 : 1e-3;
}

// "m" or "mm"; throws GeometryError for anything else.
LengthUnit parseLengthUnit(std::string_view text);

}  // namespace hg::geometry
