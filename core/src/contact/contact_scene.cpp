#include "hapticgrasp/contact/contact_scene.hpp"

#include <stdexcept>

namespace hg::contact {
namespace {

std::vector<geometry::Aabb> worldBoxes(const std::vector<ContactBody>& bodies) {
  std::vector<geometry::Aabb> boxes;
  for (const ContactBody& b : bodies) {
    if (!b.model) throw std::invalid_argument("contact scene: a part without a contact model");
    boxes.push_back(b.pose.absoluteBounds(b.model->bounds()));
  }
  return boxes;
}

}  // namespace

ContactScene::ContactScene(std::vector<ContactBody> bodies)
    : bodies_(std::move(bodies)), broadPhase_(worldBoxes(bodies_)), revisions_(bodies_.size(), 0) {}

void ContactScene::setPose(std::size_t i, const grasp::PartPose& pose) noexcept {
  bodies_[i].pose = pose;
  broadPhase_.update(i, pose.absoluteBounds(bodies_[i].model->bounds()));
  ++revisions_[i];
}

std::size_t ContactScene::nearby(const geometry::Aabb& box, int exclude, std::span<int> out) const noexcept {
  // A carried part overlaps a handful of boxes; 64 at once is plenty, and the count says more.
  int found[64];
  const std::size_t total = broadPhase_.overlapping(box, std::span<int>(found, 64));
  std::size_t written = 0, count = 0;
  for (std::size_t k = 0; k < std::min<std::size_t>(total, 64); ++k) {
    if (found[k] == exclude) continue;
    if (written < out.size()) out[written++] = found[k];
    ++count;
  }
  return count + (total > 64 ? total - 64 : 0);
}

}  // namespace hg::contact
