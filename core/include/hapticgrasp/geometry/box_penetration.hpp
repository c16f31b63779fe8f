#pragma once
// The coarsest back end: a part answered as its axis-aligned bounding box (part frame), in
// closed form. Built in nanoseconds from the box alone (no OCCT shape), so that every part
// of a scene can be touched the moment a session starts, while its own model is built in
// the background. Features: the box's faces 1-6 (-x, +x, -y, +y, -z, +z); a foot on an
// edge or a corner of the box says Edge or Vertex (index 0: the box has no B-rep).
#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/penetration.hpp"

namespace hg::geometry {

class BoxPenetration final : public PenetrationModel {
 public:
  // Throws GeometryError for an empty or non-finite box.
  explicit BoxPenetration(const Aabb& box);

  std::string_view name() const noexcept override { return "box"; }
  std::string setting() const override;  // "bounding box 40 x 20 x 10 mm"
  std::size_t memoryBytes() const noexcept override { return sizeof(*this); }
  Penetration query(const Vec3& x, QueryState& state) const noexcept override;

  const Aabb& box() const noexcept { return box_; }
  // The box as a solid of `spec`: its volume, mass, centre and inertia.
  MassProperties massProperties(const MassSpec& spec) const noexcept;

 protected:
  bool queryFeature(const Vec3& x, Feature feature, int index, double& u, double& v,
                    Penetration& out) const noexcept override;

 private:
  Aabb box_;
  Vec3 centre_, half_;
};

}  // namespace hg::geometry
