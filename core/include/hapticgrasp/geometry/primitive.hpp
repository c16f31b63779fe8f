#pragma once
// A part recognised as an analytic primitive can be answered in closed form: the
// cheapest rung of the speed/accuracy ladder, and exact.
#include "hapticgrasp/math/types.hpp"

namespace hg::geometry {

struct Primitive {
  enum class Kind { None, Cylinder, Box, Sphere } kind = Kind::None;
  Vec3 centre = Vec3::Zero();          // metres, part frame
  Mat3 axes = Mat3::Identity();        // columns: the primitive's axes (cylinder axis = z)
  Vec3 halfExtents = Vec3::Zero();     // box: half sizes along axes
  double radius = 0;                   // cylinder, sphere
  double halfLength = 0;               // cylinder: half its length along axes.col(2)
};

const char* toString(Primitive::Kind kind);

}  // namespace hg::geometry
