#pragma once
// The ONE place where FreeCAD's units and conventions meet the core's: FreeCAD lengths are
// millimetres, its Placement is Base (mm) + Rotation (quaternion x, y, z, w); the core is SI
// and keeps poses as PartPose (rotation matrix object -> absolute, position in metres).
// Every mm <-> m conversion of the FreeCAD plugin goes through these functions.
#include <array>

#include "hapticgrasp/geometry/units.hpp"
#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/math/types.hpp"

namespace hg::freecad {

// The length unit of FreeCAD documents (and of the BREP text the plugin hands over).
inline constexpr geometry::LengthUnit kDocumentUnit = geometry::LengthUnit::Millimetre;
inline constexpr double kMetresPerMm = geometry::metresPer(kDocumentUnit);

// A FreeCAD Placement as plain numbers: Base in mm, Rotation.Q as (x, y, z, w).
struct Placement {
  std::array<double, 3> base_mm{0, 0, 0};
  std::array<double, 4> quaternion{0, 0, 0, 1};
};

double toMetres(double mm);
double toMillimetres(double m);
Vec3 toMetres(const std::array<double, 3>& mm);
std::array<double, 3> toMillimetres(const Vec3& m);

// Throws std::invalid_argument for a non-finite base or a quaternion that is not finite or
// has (almost) zero norm; any other quaternion is normalised.
grasp::PartPose toPose(const Placement& placement);
// Quaternion with w >= 0 (q and -q are the same rotation).
Placement toPlacement(const grasp::PartPose& pose);

// One key of a hand script as the plugin receives it (mm; turn in rad).
struct HandKeyMm {
  double t = 0;
  std::array<double, 3> index_mm{0, 0, 0}, thumb_mm{0, 0, 0}, wrist_mm{0, 0, 0}, shift_mm{0, 0, 0};
  double turn = 0;
};
grasp::HandKey toHandKey(const HandKeyMm& key);

}  // namespace hg::freecad
