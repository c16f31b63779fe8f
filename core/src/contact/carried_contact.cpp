#include "hapticgrasp/contact/carried_contact.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace hg::contact {
namespace {

std::vector<ContactBody> bodiesOf(const grasp::Scene& scene) {
  std::vector<ContactBody> bodies(scene.size());
  for (std::size_t i = 0; i < scene.size(); ++i) bodies[i] = {scene.part(i).contact, scene.part(i).initialPose};
  return bodies;
}

const grasp::Scene& checked(const grasp::ScenePtr& scene) {
  if (!scene) throw std::invalid_argument("carried contact: no scene");
  return *scene;
}

}  // namespace

CarriedContact::CarriedContact(grasp::ScenePtr scene, const CarriedContactConfig& config)
    : scene_(std::move(scene)), config_(config), contactScene_(bodiesOf(checked(scene_))), swaps_(*scene_) {
  if (config.slots < 1) throw std::invalid_argument("carried contact: at least one slot");
  slots_.reserve(static_cast<std::size_t>(config.slots));
  for (int k = 0; k < config.slots; ++k) slots_.push_back({-1, VirtualCoupling(nullptr, config.coupling, config.query)});
}

CarriedContact::Slot* CarriedContact::slotOf(int part) noexcept {
  for (Slot& s : slots_)
    if (s.part == part) return &s;
  return nullptr;
}

const CarriedContact::Slot* CarriedContact::slotOf(int part) const noexcept {
  for (const Slot& s : slots_)
    if (s.part == part) return &s;
  return nullptr;
}

void CarriedContact::reset() noexcept {
  for (Slot& s : slots_) s.part = -1;
  for (std::size_t i = 0; i < contactScene_.size(); ++i) contactScene_.setPose(i, scene_->part(i).initialPose);
  report_ = {};
}

// A part's exact models came (or changed): the others meet it by its new shell. A carried
// part keeps the shell it was lifted with until it is put down, as the grasps keep its
// models.
void CarriedContact::takeSwaps() noexcept {
  swaps_.follow(*scene_, [this](int part) {
    const auto i = static_cast<std::size_t>(part);
    const ContactModelPtr& model = scene_->part(i).contact;
    if (model != contactScene_.body(i).model) contactScene_.setModel(i, model);
  });
}

void CarriedContact::beginTick() noexcept {
  report_ = {};
  takeSwaps();
}

bool CarriedContact::lift(int part, const grasp::PartPose& pose) noexcept {
  if (part < 0 || static_cast<std::size_t>(part) >= contactScene_.size()) return false;
  const ContactModelPtr& model = contactScene_.body(static_cast<std::size_t>(part)).model;
  Slot* slot = slotOf(part);
  if (!slot) slot = model ? slotOf(-1) : nullptr;
  if (!slot || !slot->coupling.rebind(model, pose)) return false;
  slot->part = part;
  letThroughWhatItInterferes(*slot, pose);
  return true;
}

// The parts it already interferes with where it stands: one look (no constraint), then
// those pairs are left out for this carry.
void CarriedContact::letThroughWhatItInterferes(Slot& slot, const grasp::PartPose& pose) noexcept {
  slot.coupling.observe(pose, contactScene_, slot.part);
  std::array<int, ContactQuery::kMaxLetThrough> through{};
  std::size_t n = 0;
  for (const Contact& c : slot.coupling.query().contacts()) {
    if (!(c.gap < -config_.interferenceAtLift_m) || n == through.size()) continue;
    if (std::find(through.begin(), through.begin() + static_cast<std::ptrdiff_t>(n), c.part) == through.begin() + static_cast<std::ptrdiff_t>(n))
      through[n++] = c.part;
  }
  slot.coupling.letThrough(std::span<const int>(through.data(), n));
  slot.coupling.reset(pose);
}

const CouplingOutput* CarriedContact::carry(int part, const grasp::PartPose& dictated, double dt) noexcept {
  Slot* s = slotOf(part);
  if (!s || part < 0) {
    ++report_.unmodelled;
    return nullptr;
  }
  if (!config_.constrain) {
    describe(part, s->coupling.observe(dictated, contactScene_, part));
    return nullptr;
  }
  const CouplingOutput& out = s->coupling.step(dictated, dt, contactScene_, part);
  // Another carried part meets this one where it is now: only while another is carried,
  // as the move costs the others' caches of it.
  const auto carried = std::count_if(slots_.begin(), slots_.end(), [](const Slot& k) { return k.part >= 0; });
  if (carried > 1) contactScene_.setPose(static_cast<std::size_t>(part), out.pose);
  describe(part, out);
  return &out;
}

// The report tells of the carried part nearest another.
void CarriedContact::describe(int part, const CouplingOutput& out) noexcept {
  ++report_.carried;
  const Clearance& c = out.clearance;
  if (const Slot* s = slotOf(part)) report_.letThrough += static_cast<int>(s->coupling.query().lettingThrough().size());
  if (report_.part >= 0 && !(c.distance_m < report_.clearance_m)) return;
  report_.part = part;
  report_.clearance_m = c.distance_m;
  report_.clearanceExact = c.exact;
  report_.otherPart = c.part;
  report_.heldFace = c.heldFace;
  report_.otherFace = c.otherFace;
  report_.heldPoint = c.heldPoint;
  report_.otherPoint = c.otherPoint;
  report_.penetration_m = out.penetration_m;
  report_.contactForce_N = out.contactForce_N;
  report_.couplingForce_N = out.force_N;
  report_.couplingTorque_Nm = out.torque_Nm;
  report_.contacts = out.contacts;
  report_.active = out.active;
  report_.substeps = out.substeps;
  report_.queried = out.queried;
  report_.lagging = out.lagging;
  report_.saturated = out.saturated;
  report_.passivityEnergy_J = out.passivityEnergy_J;
  report_.rotationalPassivityEnergy_J = out.rotationalPassivityEnergy_J;
}

void CarriedContact::putDown(int part, const grasp::PartPose& pose) noexcept {
  if (part < 0 || static_cast<std::size_t>(part) >= contactScene_.size()) return;
  if (Slot* s = slotOf(part)) s->part = -1;
  contactScene_.setPose(static_cast<std::size_t>(part), pose);
}

}  // namespace hg::contact
