#include "hapticgrasp/contact/contact_scene.hpp"

#include <algorithm>

namespace hg::contact {

ContactScene::ContactScene(std::vector<ContactBody> bodies) : bodies_(std::move(bodies)), revisions_(bodies_.size(), 0) {
  std::vector<geometry::Aabb> boxes;
  boxes.reserve(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i) boxes.push_back(worldBox(i));
  broadPhase_ = grasp::BroadPhase(boxes);
}

// A part without a model stands in the tree as the point where it is: the tree stays well
// formed, and nearby() leaves the part out whatever overlaps it.
geometry::Aabb ContactScene::worldBox(std::size_t i) const noexcept {
  const ContactBody& b = bodies_[i];
  if (b.model) return b.pose.absoluteBounds(b.model->bounds());
  return {b.pose.position, b.pose.position};
}

void ContactScene::setPose(std::size_t i, const grasp::PartPose& pose) noexcept {
  bodies_[i].pose = pose;
  broadPhase_.update(i, worldBox(i));
  ++revisions_[i];
}

void ContactScene::setModel(std::size_t i, ContactModelPtr model) noexcept {
  bodies_[i].model = std::move(model);
  broadPhase_.update(i, worldBox(i));
  ++revisions_[i];
}

std::size_t ContactScene::nearby(const geometry::Aabb& box, int exclude, std::span<int> out) const noexcept {
  // A carried part overlaps a handful of boxes; 64 at once is plenty, and the count says more.
  int found[64];
  const std::size_t total = broadPhase_.overlapping(box, std::span<int>(found, 64));
  std::size_t written = 0, count = 0;
  for (std::size_t k = 0; k < std::min<std::size_t>(total, 64); ++k) {
    if (found[k] == exclude || !bodies_[static_cast<std::size_t>(found[k])].model) continue;
    if (written < out.size()) out[written++] = found[k];
    ++count;
  }
  return count + (total > 64 ? total - 64 : 0);
}

}  // namespace hg::contact
