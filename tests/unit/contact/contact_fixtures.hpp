#pragma once
// Parts for the contact tests, built with OpenCASCADE at real size (mm, as a CAD file
// would hold them) and modelled as a scene would: a peg, a block with a chamfered hole
// 0.1 mm wider than the peg, a 0.5 mm plate, plain boxes.
#include <BRepAdaptor_Surface.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <TopoDS.hxx>
#include <cmath>
#include <gp_Ax1.hxx>
#include <gp_Ax2.hxx>
#include <gp_Trsf.hxx>
#include <numbers>
#include <vector>

#include "hapticgrasp/contact/contact_scene.hpp"
#include "hapticgrasp/geometry/backends.hpp"

namespace hg::test {

using contact::ContactBody;
using contact::ContactModel;
using contact::ContactModelPtr;
using geometry::LengthUnit;
using geometry::PartModel;

inline ContactModelPtr contactModelOf(const TopoDS_Shape& shape, const char* name, int maxPoints = 1024) {
  const auto part = PartModel::fromShape(shape, LengthUnit::Millimetre, name);
  contact::ContactModelOptions options;
  options.maxPoints = maxPoints;
  return ContactModel::build(part, geometry::makePenetration(part), options);
}

// A box [x0, x0+dx] x [y0, y0+dy] x [z0, z0+dz], mm.
inline ContactModelPtr boxModel(double x0, double y0, double z0, double dx, double dy, double dz,
                                int maxPoints = 1024) {
  return contactModelOf(BRepPrimAPI_MakeBox(gp_Pnt(x0, y0, z0), dx, dy, dz).Shape(), "box", maxPoints);
}

// The peg: diameter 10 mm, 40 mm long, axis z, its bottom face at z = 0.
inline constexpr double kPegDiameter_mm = 10.0;
inline ContactModelPtr pegModel(int maxPoints = 600) {
  return contactModelOf(
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), kPegDiameter_mm / 2, 40).Shape(), "peg",
      maxPoints);
}

// A 40 x 40 x 20 mm block, top face at z = 0, with a through hole on z of diameter
// peg + clearance, its rim chamfered 0.5 mm at 45 degrees.
inline ContactModelPtr holeBlockModel(double clearance_mm = 0.1) {
  const double r = (kPegDiameter_mm + clearance_mm) / 2;
  TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(-20, -20, -20), 40, 40, 20).Shape();
  block = BRepAlgoAPI_Cut(block, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -25), gp_Dir(0, 0, 1)), r, 30).Shape())
              .Shape();
  block =
      BRepAlgoAPI_Cut(block, BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(0, 0, -0.5), gp_Dir(0, 0, 1)), r, r + 1.0, 1.0).Shape())
          .Shape();
  return contactModelOf(block, "hole block");
}

// A plate `thickness_mm` thick, 60 x 60 mm, its top face at z = 0.
inline ContactModelPtr plateModel(double thickness_mm = 0.5) {
  return boxModel(-30, -30, -thickness_mm, 60, 60, thickness_mm);
}

// A pose at `position_m` turned by `angle_rad` about `axis`.
inline grasp::PartPose poseAt(const Vec3& position_m, double angle_rad = 0, const Vec3& axis = Vec3::UnitX()) {
  grasp::PartPose p;
  p.rotation = Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
  p.position = position_m;
  return p;
}

inline contact::ContactScene sceneOf(std::vector<ContactModelPtr> models) {
  std::vector<ContactBody> bodies;
  for (auto& m : models) bodies.push_back({m, grasp::PartPose{}});
  return contact::ContactScene(std::move(bodies));
}

}  // namespace hg::test
