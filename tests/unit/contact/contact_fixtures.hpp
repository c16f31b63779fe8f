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

#include <algorithm>

#include "hapticgrasp/contact/contact_scene.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/grasp/hand_sample.hpp"
#include "hapticgrasp/scene/scene.hpp"

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

// ---- A grasp scene with contact: a block over a plate, and a hand that lowers it onto it ----

inline constexpr double kMm = 1e-3;
inline constexpr double kPlateTop = -2 * kMm;  // 2 mm below the block's bottom face at rest

// A box part as a scene holds it (mm on the way in, metres inside), with its contact shell.
inline grasp::ScenePart boxPart(double x0, double y0, double z0, double dx, double dy, double dz, double mass_kg) {
  const auto model = PartModel::fromShape(BRepPrimAPI_MakeBox(gp_Pnt(x0, y0, z0), dx, dy, dz).Shape(),
                                          LengthUnit::Millimetre, "box");
  grasp::ScenePart part = grasp::makeScenePart(model, geometry::MassSpec::mass(mass_kg), grasp::PartPose{});
  part.contact = ContactModel::build(part.model, part.penetration);
  return part;
}

// Part 0: a 20 mm cube on [-10, 10]² x [0, 20] mm; part 1: a plate whose top is 2 mm below it.
inline std::vector<grasp::ScenePart> blockOverPlateParts(double mass_kg) {
  std::vector<grasp::ScenePart> parts;
  parts.push_back(boxPart(-10, -10, 0, 20, 20, 20, mass_kg));
  parts.push_back(boxPart(-40, -40, kPlateTop / kMm - 5, 80, 80, 5, 1.0));
  return parts;
}
inline grasp::ScenePtr blockOverPlate(double mass_kg) {
  return std::make_shared<const grasp::Scene>(blockOverPlateParts(mass_kg));
}

// The hand at time t: fingertips on x at the cube's mid-height (index at +x), the wrist off
// to -y, all shifted by dz; between keys, linear.
struct HandKey {
  double t, index_mm, thumb_mm, dz_mm;
};
inline grasp::HandSample handAt(const std::vector<HandKey>& keys, double t) {
  auto b = std::upper_bound(keys.begin(), keys.end(), t, [](double x, const HandKey& k) { return x < k.t; });
  if (b == keys.end()) b = keys.end() - 1;
  const HandKey& a = *(b == keys.begin() ? b : b - 1);
  const double u = b->t > a.t ? std::clamp((t - a.t) / (b->t - a.t), 0.0, 1.0) : 1.0;
  const auto mix = [&](double x, double y) { return ((1 - u) * x + u * y) * kMm; };
  const double z = 10 * kMm + mix(a.dz_mm, b->dz_mm);
  grasp::HandSample h;
  h.index = Vec3(mix(a.index_mm, b->index_mm), 0, z);
  h.thumb = Vec3(mix(a.thumb_mm, b->thumb_mm), 0, z);
  h.wrist = Vec3(0, -100 * kMm, z);
  return h;
}

// Close on the cube `depth_mm` into its faces, squeeze 0.2 mm more, lift 2 mm, lower 6 mm
// (4 mm past the plate's top), hold, open: 1.9 s.
inline std::vector<HandKey> lowerOntoPlate(double depth_mm) {
  const double in = 10 - depth_mm, squeezed = in - 0.2;
  return {{0.0, 14, -14, 0},          {0.1, in, -14, 0},
          {0.2, in, -in, 0},          {0.3, squeezed, -squeezed, 0},
          {0.6, squeezed, -squeezed, 2}, {1.2, squeezed, -squeezed, -6},
          {1.5, squeezed, -squeezed, -6}, {1.7, 14, -14, -6},
          {1.9, 14, -14, -6}};
}

}  // namespace hg::test
