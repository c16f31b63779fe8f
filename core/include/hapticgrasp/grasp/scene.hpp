#pragma once
// The parts a hand can touch: an immutable model, built once and shared read-only by the
// servo thread. Where each part is now is per-tick data and lives in the grasp
// (TwoFingerGrasp), not here.
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"

namespace hg::grasp {

struct ScenePart {
  geometry::PartModelPtr model;              // surfaces, bounds (object frame, metres)
  geometry::PenetrationModelPtr penetration; // P_o of eqs 4-5; must be real-time safe
  geometry::MassProperties mass;             // M_o and x_g^o of eqs 29-30
  PartPose initialPose;                      // where the part rests before anyone moves it
};

// The usual way to make one: mass properties from the B-rep, penetration back end `backend`
// (analytic for a recognised primitive, exact otherwise).
ScenePart makeScenePart(geometry::PartModelPtr model, const geometry::MassSpec& mass, const PartPose& pose,
                        geometry::Backend backend = geometry::Backend::Auto);

class Scene {
 public:
  // Throws std::invalid_argument for a missing model, a penetration back end that is not
  // real-time safe, a non-positive mass, or a pose that is not finite and a rotation.
  explicit Scene(std::vector<ScenePart> parts);

  std::size_t size() const { return parts_.size(); }
  const ScenePart& part(std::size_t i) const { return parts_[i]; }
  std::span<const ScenePart> parts() const { return parts_; }

 private:
  std::vector<ScenePart> parts_;
};

using ScenePtr = std::shared_ptr<const Scene>;

}  // namespace hg::grasp
