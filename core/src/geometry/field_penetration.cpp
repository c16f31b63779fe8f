// The `field` penetration back end: an OpenVDB narrow-band signed distance field sampled
// trilinearly. Fast and allocation-free per query, accurate to about a voxel; its build
// takes seconds to minutes and much memory at fine voxels, so it runs on its own thread
// with progress and cancel (FieldBuild).
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/util/NullInterrupter.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/tessellation.hpp"

namespace hg::geometry {
namespace {

using Grid = openvdb::FloatGrid;

// The mesh is a means, not the result: a tenth of a voxel keeps its chord error well
// below the field's own trilinear error. On large radii the angle between facets governs
// instead: at OCCT's default 0.3 rad the field's normals showed the facets (rms 1 degree
// on a 40 mm sphere at 1 mm voxels); 0.1 rad halves that for twice the triangles.
constexpr double kDeflectionPerVoxel = 0.1;
constexpr double kAngularDeflection_rad = 0.1;
// The normal is a central difference of the trilinear field one voxel either side. OpenVDB's
// values carry local bumps of up to ~0.2 voxel; half a voxel either side turned those into
// normals up to 9 degrees off on a sphere, one voxel into at most 4.5 degrees.
constexpr double kGradientStep_voxels = 1.0;
// The band must hold the benchmark's +/-5 mm shell with margin, plus the gradient stencil
// and the trilinear cell (2 voxels) so that no sample inside 6 mm reads the background.
constexpr double kMinBandWidth_m = 6e-3;
constexpr double kStencilVoxels = 2.0;
// Share of progress() given to tessellation (not interruptible, no progress of its own).
constexpr double kTessellatedProgress = 0.1;
// Beyond this index coordinate, int32 voxel coordinates would overflow: no field there.
constexpr double kMaxIndexCoordinate = 1 << 30;

void initialiseOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

void raiseTo(std::atomic<double>& progress, double value) {
  // Many TBB workers report at once: keep progress() monotone.
  double current = progress.load(std::memory_order_relaxed);
  while (current < value && !progress.compare_exchange_weak(current, value, std::memory_order_relaxed)) {
  }
}

void throwIfCancelled(const std::atomic<bool>& cancelled) {
  if (cancelled.load()) throw GeometryError("field build cancelled");
}

// OpenVDB's interrupter interface: meshToVolume asks wasInterrupted() from its worker
// threads, with a percentage at its phase boundaries and without one (-1) once per
// triangle while voxelising.
class BuildInterrupter final : public openvdb::util::NullInterrupter {
 public:
  BuildInterrupter(std::atomic<double>& progress, const std::atomic<bool>& cancelled, std::size_t triangles)
      : progress_(progress), cancelled_(cancelled), triangles_(std::max<std::size_t>(triangles, 1)) {}

  bool wasInterrupted(int percent = -1) override {
    raiseTo(progress_, kTessellatedProgress + (1.0 - kTessellatedProgress) * fraction(percent));
    return cancelled_.load(std::memory_order_relaxed);
  }

 private:
  // Voxelisation is the first 30 % of meshToVolume by OpenVDB's own estimate; within it,
  // count triangles (large ones are split into several tasks, hence the cap).
  double fraction(int percent) {
    if (percent >= 0) return std::min(percent, 100) / 100.0;
    const auto calls = calls_.fetch_add(1, std::memory_order_relaxed) + 1;
    return 0.30 * std::min(1.0, double(calls) / double(triangles_));
  }

  std::atomic<double>& progress_;
  const std::atomic<bool>& cancelled_;
  const std::size_t triangles_;
  std::atomic<std::size_t> calls_{0};
};

class FieldPenetration final : public PenetrationModel {
 public:
  FieldPenetration(Grid::ConstPtr grid, double voxel_m)
      : grid_(std::move(grid)), voxel_(voxel_m), background_(grid_->background()) {}

  std::string_view name() const noexcept override { return "field"; }
  std::string setting() const override {
    std::ostringstream text;
    text << "voxel " << voxel_ * 1e3 << " mm";
    return text.str();
  }
  std::size_t memoryBytes() const noexcept override { return grid_->memUsage(); }

  Penetration query(const Vec3& x, QueryState& state) const noexcept override;

 private:
  // A stack-local accessor without registration: no heap, no lock, and no sharing
  // between threads (a stored accessor would be all three). It caches the leaf, so the
  // seven trilinear samples of one query walk the tree about once.
  using Accessor = Grid::ConstUnsafeAccessor;

  static double sample(const Accessor& field, const openvdb::Vec3d& index) {
    return openvdb::tools::BoxSampler::sample(field, index);
  }
  Vec3 gradient(const Accessor& field, const openvdb::Vec3d& index) const;
  Penetration beyondBand(double value) const;

  const Grid::ConstPtr grid_;
  const double voxel_;
  const double background_;  // the band's half-width in metres, the value outside it
};

// Central differences of the trilinear field (kGradientStep_voxels either side): smoother
// across cell faces than the gradient of one cell's interpolant.
Vec3 FieldPenetration::gradient(const Accessor& field, const openvdb::Vec3d& index) const {
  Vec3 g;
  for (int axis = 0; axis < 3; ++axis) {
    openvdb::Vec3d step(0.0);
    step[axis] = kGradientStep_voxels;
    g[axis] = (sample(field, index + step) - sample(field, index - step)) / (2 * kGradientStep_voxels * voxel_);
  }
  return g;
}

// Outside the band the field holds only its sign (a tile value of +/-background): no foot,
// no normal, and the depth is only a bound.
Penetration FieldPenetration::beyondBand(double value) const {
  Penetration out;
  out.inside = value < 0;
  out.depth = out.inside ? background_ : -background_;
  return out;
}

Penetration FieldPenetration::query(const Vec3& x, QueryState& state) const noexcept {
  state.feature = Feature::None;
  state.index = 0;
  if (!x.allFinite()) return Penetration{};
  const openvdb::Vec3d index = grid_->transform().worldToIndex(openvdb::Vec3d(x.x(), x.y(), x.z()));
  if (std::abs(index[0]) > kMaxIndexCoordinate || std::abs(index[1]) > kMaxIndexCoordinate ||
      std::abs(index[2]) > kMaxIndexCoordinate)
    return beyondBand(background_);

  const Accessor field(grid_->tree());
  const double d = sample(field, index);  // OpenVDB level sets are negative inside
  if (std::abs(d) >= background_) return beyondBand(d);

  Penetration out;
  out.inside = d < 0;
  out.depth = -d;
  const Vec3 g = gradient(field, index);
  const double norm = g.norm();
  // On a medial surface inside the band (a thin wall's mid-plane) the gradient vanishes:
  // the sign and depth still hold, the direction does not.
  if (!(norm > 1e-3)) {
    out.foot = x;
    return out;
  }
  out.normal = g / norm;
  out.foot = x - d * out.normal;
  out.vector = x - out.foot;
  out.feature = Feature::Face;  // a field names no B-rep feature: featureIndex stays 0
  state.feature = Feature::Face;
  return out;
}

// The mesh in index space, in double before the cast to float: the transform carries the
// part's offset, so float index coordinates stay small wherever the part sits.
void toIndexSpace(const Tessellation& mesh, const openvdb::math::Transform& transform,
                  std::vector<openvdb::Vec3s>& points, std::vector<openvdb::Vec3I>& triangles) {
  points.reserve(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices)
    points.emplace_back(transform.worldToIndex(openvdb::Vec3d(v.x(), v.y(), v.z())));
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    triangles.emplace_back(openvdb::Index32(t[0]), openvdb::Index32(t[1]), openvdb::Index32(t[2]));
}

Grid::Ptr meshToField(const Tessellation& mesh, const Vec3& origin, double voxel_m,
                      BuildInterrupter& interrupter) {
  auto transform = openvdb::math::Transform::createLinearTransform(voxel_m);
  transform->postTranslate(openvdb::Vec3d(origin.x(), origin.y(), origin.z()));
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  toIndexSpace(mesh, *transform, points, triangles);
  const openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(points, triangles);
  const float band = float(std::ceil(kMinBandWidth_m / voxel_m - 1e-6) + kStencilVoxels);
  return openvdb::tools::meshToVolume<Grid>(interrupter, adapter, *transform, band, band);
}

PenetrationModelPtr buildField(const PartModelPtr& part, double voxel_m, std::atomic<double>& progress,
                               const std::atomic<bool>& cancelled) {
  initialiseOpenVdb();
  throwIfCancelled(cancelled);
  const Tessellation mesh = tessellate(*part, voxel_m * kDeflectionPerVoxel, kAngularDeflection_rad);
  if (mesh.triangles.empty()) throw GeometryError("field build: the part has no triangles");
  raiseTo(progress, kTessellatedProgress);
  throwIfCancelled(cancelled);

  BuildInterrupter interrupter(progress, cancelled, mesh.triangles.size());
  Grid::Ptr grid = meshToField(mesh, part->bounds().min, voxel_m, interrupter);
  // meshToVolume returns its partial grid when interrupted; that grid is no field.
  throwIfCancelled(cancelled);
  if (!grid || grid->tree().activeVoxelCount() == 0) throw GeometryError("field build: empty distance field");
  progress.store(1.0);
  return std::make_shared<FieldPenetration>(std::move(grid), voxel_m);
}

// Every failure leaves the worker as a GeometryError, the one error get() promises.
PenetrationModelPtr buildFieldOrThrow(const PartModelPtr& part, double voxel_m, std::atomic<double>& progress,
                                      const std::atomic<bool>& cancelled) {
  try {
    return buildField(part, voxel_m, progress, cancelled);
  } catch (const GeometryError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw GeometryError("field build ran out of memory (voxel " + std::to_string(voxel_m * 1e3) + " mm)");
  } catch (const std::exception& e) {
    throw GeometryError(std::string("field build failed: ") + e.what());
  } catch (...) {
    throw GeometryError("field build failed");
  }
}

}  // namespace

FieldBuild::FieldBuild(PartModelPtr part, double voxel_m) {
  if (!part) throw GeometryError("field build: no part");
  if (!(voxel_m > 0) || !std::isfinite(voxel_m)) throw GeometryError("field build: voxel size must be positive");
  if (part->characteristicLength() / voxel_m > kMaxIndexCoordinate / 4)
    throw GeometryError("field build: voxel too small for the part");
  // The lambda owns its copy of the part; `this` outlives the task because ~FieldBuild waits.
  result_ = std::async(std::launch::async, [this, part = std::move(part), voxel_m] {
    return buildFieldOrThrow(part, voxel_m, progress_, cancelled_);
  });
}

FieldBuild::~FieldBuild() {
  cancel();
  if (result_.valid()) result_.wait();
}

bool FieldBuild::ready() const {
  return result_.valid() && result_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

PenetrationModelPtr FieldBuild::get() {
  // std::future hands its value out once: a second get() is a caller's error, reported as such.
  if (!result_.valid()) throw GeometryError("field build: result already taken");
  return result_.get();
}

PenetrationModelPtr makeFieldPenetration(PartModelPtr part, double voxel_m) {
  FieldBuild build(std::move(part), voxel_m);
  return build.get();
}

}  // namespace hg::geometry
