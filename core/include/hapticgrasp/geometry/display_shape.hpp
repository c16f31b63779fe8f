#pragma once
// A shape from someone else, made safe to show in FreeCAD. A recording's attached part is
// binary BREP that anyone may have written; the Review panel hands it to FreeCAD, whose
// display meshes it with no limit (an edge 98 times round kept BRepMesh busy for good). So
// before FreeCAD meets it, the shape is read, checked as a session's part load checks it
// (PartModel::fromShape) and, when asked, meshed once as FreeCAD's display will mesh it. In
// the workbench this runs in the loader process, under its time limit: a shape whose display
// mesh would not finish, or that crashes the reader, is an error there, never a FreeCAD that
// hangs or dies.
//
// FreeCAD 0.20's Part view provider meshes with BRepMesh_IncrementalMesh at a deflection of
// the bounding box's (dx + dy + dz) / 300 times its Deviation (0.5 by default), an angular
// deflection of 28.5° and relative off; the same OCCT (Debian's 7.6, which FreeCAD links)
// meshing the same shape with the same parameters does the same work.
#include <string>
#include <string_view>

#include "hapticgrasp/geometry/units.hpp"

namespace hg::geometry {

struct DisplayCheck {
  bool mesh = false;           // mesh the shape as FreeCAD's display will (only where it cannot hang FreeCAD)
  double deviation = 0.5;      // FreeCAD's default Deviation
  double angle_deg = 28.5;     // FreeCAD's default angular deflection
};

// The shape `binaryBrep` holds, checked, as OCCT text BREP without triangles (what FreeCAD's
// importBrepFromString reads). Throws GeometryError whose message completes "its recorded
// shape ...": "is not a binary BREP (why)", "is refused: why", "cannot be shown: why".
std::string displayableBrepText(std::string_view binaryBrep, LengthUnit unit, const std::string& name,
                                const DisplayCheck& check = {});

}  // namespace hg::geometry
