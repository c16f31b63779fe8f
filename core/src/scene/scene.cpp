#include "hapticgrasp/scene/scene.hpp"

#include "hapticgrasp/geometry/box_penetration.hpp"

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
  part.bounds = model->bounds();
  part.model = std::move(model);
  part.initialPose = pose;
  return part;
}

ScenePart makeCoarseScenePart(const geometry::Aabb& bounds, const geometry::MassSpec& mass, const PartPose& pose) {
  auto box = std::make_shared<const geometry::BoxPenetration>(bounds);
  ScenePart part;
  part.mass = box->massProperties(mass);
  part.penetration = std::move(box);
  part.bounds = bounds;
  part.initialPose = pose;
  part.coarse = true;
  return part;
}

namespace {

// Checks part i, and gives it its model's bounds if it has none.
void validate(ScenePart& p, std::size_t i) {
  const std::string which = "scene part " + std::to_string(i);
  if ((!p.model && !p.coarse) || !p.penetration)
    throw std::invalid_argument(which + " lacks a model or a penetration back end");
  if (p.bounds.empty() && p.model) p.bounds = p.model->bounds();
  if (p.bounds.empty() || !p.bounds.min.allFinite() || !p.bounds.max.allFinite())
    throw std::invalid_argument(which + " has no finite bounds");
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

}  // namespace

Scene::Scene(std::vector<ScenePart> parts)
    : size_(parts.size()), current_(std::make_unique<std::atomic<const ScenePart*>[]>(parts.size())) {
  for (std::size_t i = 0; i < parts.size(); ++i) validate(parts[i], i);
  owned_.reserve(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    owned_.push_back(std::make_unique<const ScenePart>(std::move(parts[i])));
    current_[i].store(owned_.back().get(), std::memory_order_relaxed);
  }
}

const ScenePart& Scene::publish(std::size_t i, ScenePart models) const {
  if (i >= size_) throw std::out_of_range("scene part " + std::to_string(i) + " of " + std::to_string(size_));
  models.initialPose = part(i).initialPose;
  validate(models, i);
  std::lock_guard lock(mutex_);
  owned_.push_back(std::make_unique<const ScenePart>(std::move(models)));
  const ScenePart* stored = owned_.back().get();
  current_[i].store(stored, std::memory_order_release);
  const std::uint64_t k = publications_.load(std::memory_order_relaxed);  // publishers hold the mutex
  publishedLog_[k % kPublicationLog].store(static_cast<int>(i), std::memory_order_relaxed);
  publications_.store(k + 1, std::memory_order_release);
  return *stored;
}

int Scene::publishedPart(std::uint64_t k) const {
  const std::uint64_t before = publications_.load(std::memory_order_acquire);
  if (k >= before || before - k >= kPublicationLog) return -1;
  const int part = publishedLog_[k % kPublicationLog].load(std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_acquire);
  // A publisher may be overwriting the entry meanwhile (it writes publication k + log
  // before counting it): then it is lost.
  return publications_.load(std::memory_order_relaxed) - k >= kPublicationLog ? -1 : part;
}

}  // namespace hg::grasp
