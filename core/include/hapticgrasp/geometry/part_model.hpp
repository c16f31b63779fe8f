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

// How much a part is checked while it is loaded (PartModel::LoadOptions). Every load checks
// that the shape is one solid or a compound of solids, closed (no free edges), valid for
// BRepCheck_Analyzer and of positive volume; these options only concern the costlier checks.
struct PartLoadOptions {
  // Reject shapes whose faces cross or coincide, within one solid or between the solids
  // of a compound, and compounds whose solids overlap, touch or nest (GeometryError
  // "self-intersecting shape: ..."): their penetration depths and mass properties would
  // be wrong. Costs ~0.05 s for the 58-face sample block and ~0.4 s for the 1030-face
  // plate (of ~3 s in all; BRepCheck_Analyzer takes most of the rest). Turn it off only for
  // shapes a CAD system has already validated (FreeCAD's Check geometry with the BOP
  // check, a fresh boolean result): every other check still runs.
  bool checkSelfIntersection = true;
  // Run the checks on OCCT's thread pool (all cores). Turn off when loading beside threads
  // that must keep their cores.
  bool parallel = true;
};

class PartModel {
 public:
  using LoadOptions = PartLoadOptions;

  // BREP text as FreeCAD's Shape.exportBrepToString() writes it (without the Placement).
  static PartModelPtr fromBrepText(std::string_view text, LengthUnit unit, std::string name = "part",
                                   const LoadOptions& options = {});
  // A .brep/.brp or .step/.stp file. STEP files carry their own unit: OCCT converts them to
  // millimetres and `unit` is ignored.
  static PartModelPtr fromFile(const std::filesystem::path& path, LengthUnit unit, const LoadOptions& options = {});
  // Every factory throws GeometryError, with a message naming the problem, for a shape that
  // cannot be used; a part that loads may carry warnings() about what was repaired.
  static PartModelPtr fromShape(const TopoDS_Shape& shape, LengthUnit unit, std::string name = "part",
                                const LoadOptions& options = {});

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
