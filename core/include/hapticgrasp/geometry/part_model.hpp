#pragma once
// An immutable model of one rigid part, built once from a B-rep and shared read-only by
// every penetration back end and every servo thread.
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Shape.hxx>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/geometry/backend.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/primitive.hpp"
#include "hapticgrasp/geometry/units.hpp"

namespace hg::geometry {

class PartModel;
using PartModelPtr = std::shared_ptr<const PartModel>;

// How a part is checked while it is loaded (PartModel::LoadOptions). Every load checks that
// the shape is one solid or a compound of solids (open shells are sewn first), closed, valid
// for BRepCheck and of positive volume. A part that fails only the validity or crossing
// checks is not refused: it is healed with ShapeFix, or answered by a back end that does not
// depend on its defect (backendChoice() says which and why).
struct PartLoadOptions {
  // Search for faces that truly cross, within one solid (a defect: the part goes to the mesh
  // back end unless ShapeFix heals it) and between the solids of a compound (their volumes
  // overlap: a warning with the overlapping volume). Tolerance-level contacts and touching
  // solids are not crossings. Costs ~0.015 s for the 58-face sample block and ~0.35 s for
  // the 1030-face plate (meshing its 1024 curved faces, coarsely). Turn it off only for
  // shapes a CAD system has already validated: every other check still runs.
  bool checkSelfIntersection = true;
  // Run the validity check and the crossing search side by side, on two threads (the sample
  // plate: 0.45 s instead of 0.8 s). Turn off when loading beside threads that must keep
  // their cores.
  bool parallel = true;
};

// How long a load took, seconds.
struct PartLoadTiming {
  double read_s = 0;   // parsing the file or text (0 for fromShape)
  double check_s = 0;  // closedness, validity, crossings, healing, overlaps
  double total_s = 0;  // all of it: reading, checks, mass properties, topology maps
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
  // The shape of a .brep or .step file, unchecked (a scene's assembly, split into parts by
  // the caller); `unit` becomes the file's (millimetres for STEP). Throws GeometryError.
  static TopoDS_Shape readFile(const std::filesystem::path& path, LengthUnit& unit);
  // Every factory throws GeometryError, with one line naming the problem, for a shape that
  // cannot be used: empty, unreadable, not a solid, or without a closed shell. A part that
  // loads may carry warnings() about what was repaired or found.
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
  // Things repaired or found while loading (an inside-out solid reversed, a defect healed,
  // solids that overlap...), one line each.
  const std::vector<std::string>& warnings() const { return warnings_; }
  // The back end that answers this part when none is asked for (makePenetration's Auto),
  // and why: exact for a valid or healed B-rep, a robust one for a defect ShapeFix cannot
  // heal. Auto still answers a recognised primitive in closed form.
  const BackendChoice& backendChoice() const { return backendChoice_; }
  const PartLoadTiming& loadTiming() const { return timing_; }

  // What the load found, besides the shape (model_cache.hpp stores it with the checked
  // shape): restoring a part from it skips the checks, the healing and the mass integrals.
  struct Record {
    double metresPerUnit = 1.0;
    Aabb bounds;
    double volume_m3 = 0;
    Vec3 centre_m = Vec3::Zero();
    Mat3 unitDensityInertia = Mat3::Zero();
    std::vector<std::string> warnings;
    BackendChoice choice;
  };
  Record record() const;
  // A part from a shape this class checked before (its shape()) and that check's record.
  // Trusts both: the caller must have verified them (the cache checksums its entries).
  // `timing`: the check's own (a load in the loader process), added to the restore's time;
  // none: the part reports the restore's time alone.
  static PartModelPtr restore(const TopoDS_Shape& checkedShape, const Record& record, std::string name,
                              const PartLoadTiming* timing = nullptr);

 private:
  PartModel() = default;
  void setShape(const TopoDS_Shape& solids);
  // Checks and models a shape whose reading took read_s, the whole load having begun at start.
  static PartModelPtr load(const TopoDS_Shape& shape, LengthUnit unit, std::string name, const LoadOptions& options,
                           double read_s, std::chrono::steady_clock::time_point start);

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
  BackendChoice backendChoice_;
  PartLoadTiming timing_;
};

}  // namespace hg::geometry
