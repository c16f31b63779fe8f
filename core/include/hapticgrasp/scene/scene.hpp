#pragma once
// The parts a hand can touch. Each part's models (surfaces, penetration back end, mass) are
// immutable and may be shared by several parts (identical shapes are modelled once); where
// a part stands is per-tick data and lives in the grasp, not here.
//
// A part's models may be replaced while the servo thread runs: a scene starts with coarse
// models built in milliseconds, and the background build publishes each part's exact ones
// as they come. publish() swaps one atomic pointer; the servo thread reads it with one
// acquire load per part(), and every model ever published stays alive as long as the
// scene, so the servo thread never frees one (nor waits for one).
#include <atomic>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"

namespace hg::contact {
class ContactModel;  // contact/contact_model.hpp
}

namespace hg::grasp {

struct ScenePart {
  geometry::PartModelPtr model;              // surfaces (object frame, metres); none for a coarse stand-in
  geometry::PenetrationModelPtr penetration; // P_o of eqs 4-5; must be real-time safe
  geometry::MassProperties mass;             // M_o and x_g^o of eqs 29-30
  geometry::Aabb bounds;                     // object frame (the Scene fills it from the model if empty)
  PartPose initialPose;                      // where the part rests before anyone moves it
  bool coarse = false;                       // a stand-in until the part's own models are built
  // Its point shell and sharp edges for part-to-part contact (contact/contact_model.hpp),
  // when the scene was built with contact; none: other parts pass through it.
  std::shared_ptr<const contact::ContactModel> contact;
};

// The usual way to make one: mass properties from the B-rep, penetration back end `backend`
// (analytic for a recognised primitive, exact otherwise).
ScenePart makeScenePart(geometry::PartModelPtr model, const geometry::MassSpec& mass, const PartPose& pose,
                        geometry::Backend backend = geometry::Backend::Auto);

// The stand-in a part answers with until its own models are built: its bounding box
// (object frame, from the shape, no model needed) in closed form, with the box's mass
// properties for `mass`. Built in nanoseconds.
ScenePart makeCoarseScenePart(const geometry::Aabb& bounds, const geometry::MassSpec& mass, const PartPose& pose);

class Scene {
 public:
  // Throws std::invalid_argument for a missing model, a penetration back end that is not
  // real-time safe, a non-positive mass, or a pose that is not finite and a rotation.
  explicit Scene(std::vector<ScenePart> parts);
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  std::size_t size() const { return size_; }
  // Part i's models now (any thread; the servo thread's read is one acquire load).
  const ScenePart& part(std::size_t i) const { return *current_[i].load(std::memory_order_acquire); }

  // Any thread but the servo's (it locks and allocates): part i is answered by `models`
  // from now on; its initial pose is kept. Validated as the constructor does (throws, and
  // nothing changes). Returns the models as stored.
  const ScenePart& publish(std::size_t i, ScenePart models) const;
  // How many publish() calls have been made (a cheap "anything new?" for readers).
  std::uint64_t publications() const { return publications_.load(std::memory_order_acquire); }
  // The part the k-th publication (0-based) was for, or -1 once the log has wrapped past
  // it (kPublicationLog later ones were made): the reader must then look at every part.
  // The servo thread refits a part's box from this, without a lock.
  int publishedPart(std::uint64_t k) const;
  static constexpr std::uint64_t kPublicationLog = 4096;

 private:
  std::size_t size_ = 0;
  std::unique_ptr<std::atomic<const ScenePart*>[]> current_;
  mutable std::mutex mutex_;  // guards owned_ (never taken by the servo thread)
  mutable std::vector<std::unique_ptr<const ScenePart>> owned_;
  mutable std::atomic<std::uint64_t> publications_{0};
  mutable std::unique_ptr<std::atomic<int>[]> publishedLog_ = std::make_unique<std::atomic<int>[]>(kPublicationLog);
};

using ScenePtr = std::shared_ptr<const Scene>;

}  // namespace hg::grasp
