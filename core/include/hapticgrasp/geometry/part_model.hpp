#pragma once
// An immutable model of one rigid part, built once from a B-rep and shared read-only by
// every penetration back end and every servo thread.
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Shape.hxx>

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/primitive.hpp"
#include "hapticgrasp/geometry/units.hpp"

namespace hg::geometry {

class PartModel;
using PartModelPtr = std::shared_ptr<const PartModel>;

class PartModel {
 public:
  // BREP text as FreeCAD's Shape.exportBrepToString() writes it (without the Placement).
  static PartModelPtr fromBrepText(std::string_view text, LengthUnit unit, std::string name = "part");
  // A .brep/.brp or .step/.stp file.
  static PartModelPtr fromFile(const std::filesystem::path& path, LengthUnit unit);
  static PartModelPtr fromShape(const TopoDS_Shape& shape, LengthUnit unit, std::string name = "part");

  const std::string& name() const { return name_; }
  // The validated shape, in the unit it was read in (see metresPerUnit()).
  const TopoDS_Shape& shape() const { return shape_; }
  double metresPerUnit() const { return metresPerUnit_; }

  // Topology, indexed 1..N as OCCT's maps are; a penetration's featureIndex refers to these.
  const TopTools_IndexedMapOfShape& faces() const { return faces_; }
  const TopTools_IndexedMapOfShape& edges() const { return edges_; }
  const TopTools_IndexedMapOfShape& vertices() const { return vertices_; }

  Aabb bounds() const { return bounds_; }                      // metres, tight
  double characteristicLength() const { return bounds_.diagonal(); }
  MassProperties massProperties(const MassSpec& spec) const;   // exact, from the B-rep
  const Primitive& primitive() const { return primitive_; }
  // Things repaired while loading (an inside-out solid reversed, ...), one line each.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  PartModel() = default;

  std::string name_;
  TopoDS_Shape shape_;
  double metresPerUnit_ = 1.0;
  TopTools_IndexedMapOfShape faces_, edges_, vertices_;
  Aabb bounds_;
  // Volume properties at unit density, SI: scaled by the MassSpec on request.
  double volume_m3_ = 0;
  Vec3 centre_m_ = Vec3::Zero();
  Mat3 unitDensityInertia_ = Mat3::Zero();
  Primitive primitive_;
  std::vector<std::string> warnings_;
};

}  // namespace hg::geometry
