#pragma once
// The penetration back ends and how to make them. Each is built once per part and shared
// read-only; each fingertip carries its own QueryState.
#include <atomic>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <string_view>

#include "hapticgrasp/geometry/backend.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/geometry/penetration.hpp"

namespace hg::geometry {

using PenetrationModelPtr = std::shared_ptr<const PenetrationModel>;

// OCCT's BRepExtrema on the shells + BRepClass3d classifier: the truth, slow, allocates.
PenetrationModelPtr makeReferencePenetration(PartModelPtr part);
// Per-feature projection over a BVH with warm starts: exact and real-time safe.
PenetrationModelPtr makeExactPenetration(PartModelPtr part);
// How the mesh back end tells inside from outside.
enum class MeshSign {
  // The angle-weighted pseudo-normal of the triangle, edge or vertex the foot lies in:
  // exact on a closed mesh that does not cross itself, and it costs nothing more.
  PseudoNormal,
  // The generalised winding number above 1/2 (winding_number.hpp): what the part encloses
  // at all, also where its faces cross or fold through each other. A cold query walks a
  // second tree (tens of us near thousands of triangles); a fingertip's QueryState carries
  // the answer while it crosses no surface.
  WindingNumber,
};
// Tessellation + Embree closest-point queries; error <= about the deflection.
PenetrationModelPtr makeMeshPenetration(PartModelPtr part, double deflection_m, MeshSign sign = MeshSign::PseudoNormal);
// Closed form for a part recognised as a cylinder, box or sphere; throws GeometryError
// if part->primitive() is None.
PenetrationModelPtr makeAnalyticPenetration(PartModelPtr part);

// An OpenVDB signed distance field takes seconds to minutes and much memory at fine voxel
// sizes: it is built on its own thread, reports progress and can be cancelled.
class FieldBuild {
 public:
  FieldBuild(PartModelPtr part, double voxel_m);
  ~FieldBuild();  // cancels and joins
  FieldBuild(const FieldBuild&) = delete;
  FieldBuild& operator=(const FieldBuild&) = delete;

  double progress() const { return progress_.load(); }  // 0..1
  void cancel() { cancelled_.store(true); }
  bool ready() const;
  // The field, once built; rethrows the build's GeometryError (or "cancelled").
  PenetrationModelPtr get();

 private:
  std::atomic<double> progress_{0.0};
  std::atomic<bool> cancelled_{false};
  std::future<PenetrationModelPtr> result_;
};
// Convenience: build on a worker and wait.
PenetrationModelPtr makeFieldPenetration(PartModelPtr part, double voxel_m);

// The defaults of the robust back ends when no setting is given: the mesh's chord
// deflection and the field's voxel size.
inline constexpr double kDefaultDeflection_m = 1e-5;
inline constexpr double kDefaultVoxel_m = 1e-3;

// Auto: the back end the part's load chose (part->backendChoice(): exact for a valid or
// healed B-rep, mesh or field for a defect it could not heal), and for a recognised
// primitive with a valid B-rep, analytic: model only what the scene requires.
// The mesh, chosen or asked for, takes its sign from the winding number where the part's
// surface may cross itself (backendChoice().surfaceMayCross), from pseudo-normals elsewhere.
PenetrationModelPtr makePenetration(PartModelPtr part, Backend backend = Backend::Auto,
                                   double setting_m = 0);

// Why the back end named `answeredBy` (a PenetrationModel's name()) answers the part under
// Auto, in one line: the part's backendChoice() reason, or the primitive's for analytic.
std::string autoBackendReason(const PartModel& part, std::string_view answeredBy);

}  // namespace hg::geometry
