#pragma once
#include "hapticgrasp/math/types.hpp"

namespace hg::geometry {

// Mass properties of a solid part in its own frame, SI.
struct MassProperties {
  double volume_m3 = 0;
  double mass_kg = 0;
  Vec3 centre_m = Vec3::Zero();        // centre of gravity, x_g^o of the first paper's eq 30
  Mat3 inertia_kgm2 = Mat3::Zero();    // about the centre of gravity, axes of the part frame
};

// How a part's mass is given: a density, or a total mass (the paper's 2 kg cylinder).
struct MassSpec {
  enum class Kind { Density, Mass } kind = Kind::Density;
  double value = 1000.0;  // kg/m^3 or kg
  static MassSpec density(double kg_per_m3) { return {Kind::Density, kg_per_m3}; }
  static MassSpec mass(double kg) { return {Kind::Mass, kg}; }
};

}  // namespace hg::geometry
