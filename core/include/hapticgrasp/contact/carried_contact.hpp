#pragma once
// Part-to-part contact for a grasp method: the parts of its grasp::Scene, each with the
// contact model the scene was built with (ScenePart::contact), and a virtual coupling for
// each part carried at once (a few slots, bound at pick-up, no allocation after
// construction). The grasp method says when a part is lifted, where the hand wants it each
// tick and where it was put down; this answers where the part may go (it stops at contact
// and slides) and the wrench the hand feels, and reports the clearance.
//
// A part lifted where it already interferes with others (a press fit, solids that overlap
// in the model: common in real assemblies) would be stuck fast; the parts it interferes
// with at pick-up let it through for that carry (counted in the report), the others stop
// it. A part without a contact model (a coarse stand-in whose shape is still being read, a
// shell that failed) is passed through, never refused: carried, it moves as the hand says
// and the report counts it `unmodelled`; standing, nothing meets it. The scene's model swaps
// are followed (coarse, then exact), as the grasp methods follow them.
//
// Everything after construction runs on the servo thread: no allocation, no lock, no throw.
#include <vector>

#include "hapticgrasp/contact/contact_report.hpp"
#include "hapticgrasp/contact/contact_scene.hpp"
#include "hapticgrasp/contact/virtual_coupling.hpp"
#include "hapticgrasp/scene/model_swaps.hpp"
#include "hapticgrasp/scene/scene.hpp"

namespace hg::contact {

struct CarriedContactConfig {
  CouplingParameters coupling;
  ContactQueryConfig query;  // query.maxPoints: the largest shell a part may have (the build's budget)
  int slots = 1;             // parts carried with contact at once
  double interferenceAtLift_m = 1e-6;  // deeper than this at pick-up: the pair lets it through
  // False: carried parts pass through the others (carry() answers nullptr) and only the
  // clearance and interference are reported: what a reviewer who wants to move freely
  // still needs to see.
  bool constrain = true;
};

class CarriedContact {
 public:
  // Every part at its initial pose. Throws std::invalid_argument for an empty scene pointer,
  // no slot, or a bad coupling (VirtualCoupling's checks).
  CarriedContact(grasp::ScenePtr scene, const CarriedContactConfig& config = {});

  // Every part back at its initial pose, nothing carried.
  void reset() noexcept;
  // A new tick: the report starts empty; model swaps published since are taken in.
  void beginTick() noexcept;
  // `part` is picked up where it stands, `pose`. False when it goes without contact: no
  // contact model yet, a shell beyond maxPoints, or every slot taken.
  bool lift(int part, const grasp::PartPose& pose) noexcept;
  // The hand dictates `dictated` for the carried `part`: the coupling's answer (the part's
  // constrained pose and the wrench on the hand), or nullptr when it goes without contact
  // (or passes through: constrain off; its clearance is reported all the same).
  const CouplingOutput* carry(int part, const grasp::PartPose& dictated, double dt) noexcept;
  // `part` was put down at `pose` (where the grasp left it, or back where it was): the
  // others meet it there from now on.
  void putDown(int part, const grasp::PartPose& pose) noexcept;

  const ContactReport& report() const noexcept { return report_; }
  const ContactScene& scene() const noexcept { return contactScene_; }
  bool carrying(int part) const noexcept { return slotOf(part) != nullptr; }

 private:
  struct Slot {
    int part = -1;  // -1: free
    VirtualCoupling coupling;
  };
  Slot* slotOf(int part) noexcept;
  const Slot* slotOf(int part) const noexcept;
  void takeSwaps() noexcept;
  void letThroughWhatItInterferes(Slot& slot, const grasp::PartPose& pose) noexcept;
  void describe(int part, const CouplingOutput& out) noexcept;

  grasp::ScenePtr scene_;
  CarriedContactConfig config_;
  ContactScene contactScene_;
  std::vector<Slot> slots_;
  grasp::ModelSwaps swaps_;
  ContactReport report_;
};

}  // namespace hg::contact
