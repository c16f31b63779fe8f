#pragma once
#include <TopoDS_Shape.hxx>

#include "hapticgrasp/geometry/primitive.hpp"

namespace hg::geometry {

// Recognises a solid that is exactly a right circular cylinder, a box or a sphere, so that
// it can be answered in closed form. `volume_m3` (from the B-rep) rules out look-alikes:
// a cylinder with a hole has the same three kinds of faces but not the same volume.
Primitive recognisePrimitive(const TopoDS_Shape& solid, double metresPerUnit, double volume_m3);

}  // namespace hg::geometry
