#pragma once
// The 6-DOF virtual coupling between the pose the hand dictates for a carried part (its
// grasp's) and the part's constrained pose (McNeely, Puterbaugh & Troy 1999; Colgate,
// Stanley & Brown 1995): a spring and damper in force and torque. The part stops at
// contact and slides along surfaces with Coulomb friction; the hand feels the coupling's
// wrench, which the grasp adds to the wrist's force and moment.
//
// Constraint-based, not penalty-based. A penalty part holds its penetration at f / k_c
// and must be integrated stiffly (0.05 mm under 20 N asks for 400 kN/m, far beyond what a
// device displays); here the part is a quasi-static god object (massless, as the grasp's
// part already is between hand and weight), moved each sub-step as far towards the hand as
// the contacts allow (constraint_solver.hpp). Its penetration is the solver's residual and
// the sampling's, independent of the coupling's stiffness, which is chosen for the device
// alone; the coupling spring is then the only store of energy, and passivity observers
// (servo/passivity.hpp) watch its two ports, force on the hand's translation and torque on
// its rotation, and damp whatever energy sampling creates.
//
// No tunnelling: no point of the part moves more than `margin_m` in one sub-step, and every
// point within the margin of another part is a constraint row of that sub-step, so no
// point can cross a surface unseen, whatever the wall's thickness. Fast hand motion takes
// more sub-steps (at most maxSubsteps, ceil(d / margin)); beyond that the part lags the hand
// (a speed cap, maxSubsteps × margin per tick) rather than skipping.
//
// step() runs on the servo thread: no allocation, no lock, no throw.
#include <span>
#include <vector>

#include "hapticgrasp/contact/constraint_solver.hpp"
#include "hapticgrasp/contact/contact_query.hpp"
#include "hapticgrasp/contact/contact_reduction.hpp"
#include "hapticgrasp/servo/passivity.hpp"

namespace hg::contact {

struct CouplingParameters {
  CouplingStiffness stiffness;  // k_t [N/m], k_r [N m/rad]
  double damping_Ns_m = 10;     // b_t on the hand's velocity relative to the part
  double rotationalDamping_Nms_rad = 0.02;
  double friction = 0.3;     // μ between parts
  double margin_m = 2.5e-4;  // the largest move of any point in one sub-step
  int maxSubsteps = 8;
  int solverIterations = 40;
  double rowSlack_m = 1e-5;  // rows: contacts within twice the sub-step's move plus this
  int maxRows = 128;         // after reduction, the closest ones when more
  double maxForce_N = 40;    // the device's limits: the displayed wrench saturates
  double maxTorque_Nm = 4;
  bool passivityController = true;  // damp a port when its observed energy goes negative
  double maxPassivityDamping_Ns_m = 200;
  double maxRotationalPassivityDamping_Nms_rad = 0.5;
};

struct CouplingOutput {
  grasp::PartPose pose;                // the part's constrained pose
  Vec3 force_N = Vec3::Zero();         // the coupling's force on the hand, at handCentre
  Vec3 torque_Nm = Vec3::Zero();       // and its moment
  Vec3 handCentre = Vec3::Zero();      // world: the part's centre where the hand wants it
  Vec3 contactForce_N = Vec3::Zero();  // what the other parts do to the part: in contact, the spring's pull it balances
  int contacts = 0;                    // rows within the margin (last sub-step)
  int active = 0;                      // of which pushing
  int substeps = 0;
  int queried = 0;               // exact point queries this tick
  double penetration_m = 0;      // deepest interpenetration seen this tick (>= 0)
  Clearance clearance;           // from the last sub-step's query
  bool saturated = false;        // the wrench was cut to the device's limits
  bool lagging = false;          // the hand moved farther than maxSubsteps sub-steps allow
  double passivityEnergy_J = 0;  // the translational port's E: >= 0 while it is passive
  double passivityDamping_Ns_m = 0;
  double rotationalPassivityEnergy_J = 0;  // the rotational port's
  double rotationalPassivityDamping_Nms_rad = 0;
};

class VirtualCoupling {
 public:
  // `held` may be none: the coupling is unbound (step() leaves everything as it was) until
  // rebind(). Throws std::invalid_argument for non-positive stiffness, margin or sub-steps.
  VirtualCoupling(ContactModelPtr held, const CouplingParameters& parameters = {},
                  const ContactQueryConfig& query = {});

  // The part is at `pose`, in no contact history (pick-up, teleport).
  void reset(const grasp::PartPose& pose) noexcept;
  // Another part to carry, at `pose`: false (and nothing changes) when its shell exceeds
  // the query's maxPoints. No allocation.
  bool rebind(ContactModelPtr held, const grasp::PartPose& pose) noexcept;
  const ContactModel& held() const noexcept { return *held_; }  // bound only
  void letThrough(std::span<const int> parts) noexcept { query_.letThrough(parts); }
  bool bound() const noexcept { return held_ != nullptr; }
  // One servo tick: the hand dictates `hand` for the part; `held` is the part's index in
  // `scene` (-1: not one of its parts).
  const CouplingOutput& step(const grasp::PartPose& hand, double dt, const ContactScene& scene, int held) noexcept;
  // The part goes where the hand says (contact off: it passes through): only its contacts
  // and clearance there, no constraint and no wrench. Interference shows as a negative
  // clearance and the penetration. Same guarantees as step().
  const CouplingOutput& observe(const grasp::PartPose& hand, const ContactScene& scene, int held) noexcept;

  const CouplingOutput& output() const noexcept { return out_; }
  const CouplingParameters& parameters() const noexcept { return parameters_; }
  const ContactQuery& query() const noexcept { return query_; }

 private:
  bool substep(const grasp::PartPose& hand, const ContactScene& scene, int held) noexcept;
  void wrench(const grasp::PartPose& hand, double dt) noexcept;

  ContactModelPtr held_;
  CouplingParameters parameters_;
  ContactQuery query_;
  ConstraintSolver solver_;
  ContactReduction reduction_;
  std::vector<Contact> near_, rows_;  // this sub-step's reachable contacts and rows (preallocated)
  grasp::PartPose pose_;              // constrained
  grasp::PartPose previousPose_, previousHand_;
  bool havePrevious_ = false;
  servo::PassivityPort port_;
  // The rotational port: its "position" is the hand's rotation accumulated as a rotation
  // vector (the sum of each tick's small turn), so that the observer's f·Δx is τ·Δθ.
  servo::PassivityPort rotationalPort_;
  Vec3 handTurn_ = Vec3::Zero();
  CouplingOutput out_;
};

}  // namespace hg::contact
