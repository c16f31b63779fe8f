#pragma once
// The parts a carried part can meet: each one's contact model and where it stands, with
// the scene's broad phase over their world boxes (scene/broad_phase.hpp), so that a carried
// part costs only the parts whose box its own (inflated) box overlaps, whatever the scene's
// size. Models are shared and immutable; poses are the only thing that changes, refitted
// in place (no allocation) when a part is put down somewhere else. A part may have no
// contact model (a coarse stand-in whose shape is still being read, a shell that failed):
// it is never near anything until setModel() gives it one.
#include <cstdint>
#include <span>
#include <vector>

#include "hapticgrasp/contact/contact_model.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/scene/broad_phase.hpp"

namespace hg::contact {

struct ContactBody {
  ContactModelPtr model;  // none: the part takes no part in contact
  grasp::PartPose pose;
};

class ContactScene {
 public:
  explicit ContactScene(std::vector<ContactBody> bodies);

  std::size_t size() const noexcept { return bodies_.size(); }
  const ContactBody& body(std::size_t i) const noexcept { return bodies_[i]; }
  // Part i now stands at `pose` (any thread that owns the scene; no allocation).
  void setPose(std::size_t i, const grasp::PartPose& pose) noexcept;
  // Part i is answered by `model` from now on (the scene build published its exact models);
  // none takes it out of contact. No allocation: the model's owner keeps it alive.
  void setModel(std::size_t i, ContactModelPtr model) noexcept;
  // How many times part i was moved: a cached answer about it is stale once this changes
  // (the carried part's own moves, if it is one of the scene's, touch no other's).
  std::uint64_t revision(std::size_t i) const noexcept { return revisions_[i]; }

  // The parts with a model, other than `exclude`, whose world box overlaps `box`: the first out.size()
  // are written; returns how many there are.
  std::size_t nearby(const geometry::Aabb& box, int exclude, std::span<int> out) const noexcept;

 private:
  geometry::Aabb worldBox(std::size_t i) const noexcept;

  std::vector<ContactBody> bodies_;
  grasp::BroadPhase broadPhase_;
  std::vector<std::uint64_t> revisions_;
};

}  // namespace hg::contact
