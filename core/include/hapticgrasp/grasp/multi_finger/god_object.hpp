#pragma once
// A god-object proxy per finger (the resultant-force paper's refs [7], [8]): a point that
// stays on the part's exact surface while the finger sinks in, joined to the finger by
// the grasping spring. It never passes through the part: once the finger entered through
// a face, the proxy is the finger's projection onto THAT face for as long as the finger
// stays behind the face's tangent plane (dot(x − foot, n) < 0), even past the part's
// middle or out of its far side (a thin plate pushed hard). The closest point of the
// surface would flip to the far face there, and the force with it.
//
// Coulomb friction: the proxy sticks to its last surface point while the spring's
// tangential force is within μ times its normal force, else it slides to the friction
// cone's edge. On a curved face the stuck point is kept on the tangent plane at the foot.
//
// All in the part's frame, SI. update() allocates nothing when the back end's queries
// do not (the exact back end's), never throws, and ignores non-finite input.
#include "hapticgrasp/geometry/penetration.hpp"
#include "hapticgrasp/math/types.hpp"

namespace hg::grasp::multi_finger {

struct GodObjectParams {
  double stiffness = 800;      // k of the finger–proxy spring [N/m]
  double friction = 1.0;       // μ, Coulomb
  double hysteresis_m = 1e-3;  // contact tracking at edges and vertices (PenetrationModel::track)
};

struct GodObjectContact {
  bool inContact = false;
  Vec3 proxy = Vec3::Zero();   // the god object, on the surface [m]
  Vec3 normal = Vec3::Zero();  // outward unit normal at the proxy
  Vec3 force = Vec3::Zero();   // spring force ON THE FINGER, k (proxy − x) [N]
  double normalForce = 0;      // force · normal ≥ 0 [N]
  double tangentialForce = 0;  // |tangential part| ≤ μ normalForce [N]
  double depth = 0;            // finger depth behind the held face [m]
  bool sliding = false;        // the friction cone limited the proxy this tick
  geometry::Feature feature = geometry::Feature::None;  // held feature
  int featureIndex = 0;
};

class GodObject {
 public:
  explicit GodObject(const geometry::PenetrationModel& model, const GodObjectParams& params = {}) noexcept
      : model_(&model), params_(params) {}

  // The finger at x (part frame): the proxy and the force.
  const GodObjectContact& update(const Vec3& x) noexcept;
  void reset() noexcept;

  const GodObjectContact& contact() const noexcept { return contact_; }
  const GodObjectParams& params() const noexcept { return params_; }
  void setParams(const GodObjectParams& params) noexcept { params_ = params; }

 private:
  void release() noexcept;

  const geometry::PenetrationModel* model_;
  GodObjectParams params_;
  geometry::QueryState state_;
  GodObjectContact contact_;
  double u_ = 0, v_ = 0;  // warm start on the held face
};

}  // namespace hg::grasp::multi_finger
