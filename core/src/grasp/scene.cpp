#include "hapticgrasp/grasp/scene.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hg::grasp {

ScenePart makeScenePart(geometry::PartModelPtr model, const geometry::MassSpec& mass, const PartPose& pose,
                        geometry::Backend backend) {
  if (!model) throw std::invalid_argument("scene part without a model");
  ScenePart part;
  part.mass = model->massProperties(mass);
  part.penetration = geometry::makePenetration(model, backend);
  part.model = std::move(model);
  part.initialPose = pose;
  return part;
}

Scene::Scene(std::vector<ScenePart> parts) : parts_(std::move(parts)) {
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    const ScenePart& p = parts_[i];
    const std::string which = "scene part " + std::to_string(i);
    if (!p.model || !p.penetration) throw std::invalid_argument(which + " lacks a model or a penetration back end");
    if (!p.penetration->realTimeSafe())
      throw std::invalid_argument(which + ": penetration back end '" + std::string(p.penetration->name()) +
                                  "' may not run on the servo thread");
    if (!(p.mass.mass_kg > 0) || !std::isfinite(p.mass.mass_kg) || !p.mass.centre_m.allFinite())
      throw std::invalid_argument(which + " needs a positive, finite mass and centre of gravity");
    const Mat3& R = p.initialPose.rotation;
    if (!R.allFinite() || !p.initialPose.position.allFinite() ||
        !(R.transpose() * R).isApprox(Mat3::Identity(), 1e-9) || !(R.determinant() > 0))
      throw std::invalid_argument(which + ": initial pose is not a finite rotation and position");
  }
}

}  // namespace hg::grasp
