#pragma once
// A part's immutable contact model, built once (off the servo thread) and shared read-only:
// a shell of points on its exact surface with their outward normals (Voxmap PointShell's
// point shell, McNeely et al. 1999), denser along its sharp convex edges, bounded in
// number; and the penetration back end that answers points of other parts against it.
//
// Why both: a carried part's points are queried against the parts around it, and the
// parts around it answer them exactly (their B-rep back ends). Points alone miss an edge
// of a static part that slips between two of the carried part's points (a plate's rim
// into a flat face); so each part's sharp convex edges are sampled too, and those of the
// static parts are queried against the carried part. Concave edges are left out: they can
// touch nothing that a face point near them would not touch first.
#include <memory>
#include <span>
#include <vector>

#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/math/types.hpp"

namespace hg::contact {

// One point of the shell, in the part's object frame, metres.
struct ShellPoint {
  Vec3 position = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  // outward, unit; on an edge, the bisector of its faces' normals
  double reach = 0;            // |position - centre|: how far a rotation about the centre moves it
  int face = 0;                // the B-rep face it lies on (1-based); an edge point: one of the two
  int edge = 0;                // the sharp edge it lies on (1-based), 0 for a face point
};

struct ContactModelOptions {
  int maxPoints = 1024;         // the shell's budget, edge points included
  double edgeDensity = 3;       // edge points lie this many times closer together than face points
  double sharpAngle_rad = 0.5;  // edges whose faces' normals differ by more (~29 deg) are sharp
};

class ContactModel;
using ContactModelPtr = std::shared_ptr<const ContactModel>;

class ContactModel {
 public:
  // Samples the part's faces (area-weighted, at least one point a face, so that small
  // features are never left out) and its sharp convex edges (at least two points an edge:
  // its ends, the part's corners), at one spacing h chosen so that the whole shell fits
  // options.maxPoints (faces: area / h^2 points, edges: edgeDensity * length / h). When
  // those minimums alone exceed the budget, the shell is thinned evenly to it.
  // `penetration` answers other parts' points against this one and must be real-time safe.
  // Throws std::invalid_argument for a missing part or back end, or a budget below 8.
  static ContactModelPtr build(geometry::PartModelPtr part, geometry::PenetrationModelPtr penetration,
                               const ContactModelOptions& options = {});

  // Sharp-edge points first, then face points.
  std::span<const ShellPoint> shell() const noexcept { return points_; }
  std::span<const ShellPoint> sharpEdges() const noexcept { return {points_.data(), edgePoints_}; }
  const geometry::PartModel& part() const noexcept { return *part_; }
  const geometry::PenetrationModel& penetration() const noexcept { return *penetration_; }
  const geometry::PartModelPtr& partPtr() const noexcept { return part_; }
  geometry::Aabb bounds() const noexcept { return part_->bounds(); }  // object frame, metres
  const Vec3& centre() const noexcept { return centre_; }             // of the bounds, object frame
  double radius() const noexcept { return radius_; }                  // largest reach of any point
  double spacing_m() const noexcept { return spacing_m_; }            // h, between face points
  int sharpEdgeCount() const noexcept { return sharpEdgeCount_; }

 private:
  ContactModel() = default;
  geometry::PartModelPtr part_;
  geometry::PenetrationModelPtr penetration_;
  std::vector<ShellPoint> points_;
  std::size_t edgePoints_ = 0;
  Vec3 centre_ = Vec3::Zero();
  double radius_ = 0;
  double spacing_m_ = 0;
  int sharpEdgeCount_ = 0;
};

}  // namespace hg::contact
