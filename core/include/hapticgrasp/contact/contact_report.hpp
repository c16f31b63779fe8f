#pragma once
// What a servo tick tells of part-to-part contact: the clearance between the carried part
// and the nearest other part (negative: interference, by that depth), between which faces
// and points, and the contact the coupling met. Fixed size, no pointers: it travels in the
// servo snapshot, the tick records and the recordings.
#include <limits>

#include "hapticgrasp/math/types.hpp"

namespace hg::contact {

struct ContactReport {
  int part = -1;                // the carried part reported on; -1: none carried with contact
  int carried = 0;              // parts carried with contact this tick
  int unmodelled = 0;           // parts carried without a contact model (they pass through)
  int letThrough = 0;           // parts the carried part already interfered with where it was lifted
  // Clearance to the nearest other part: exact when a shell point came within range of one,
  // else a lower bound (infinite: no part near at all).
  double clearance_m = std::numeric_limits<double>::infinity();
  bool clearanceExact = false;
  int otherPart = -1;
  int heldFace = 0, otherFace = 0;           // 1-based B-rep faces; 0: an edge or vertex
  Vec3 heldPoint = Vec3::Zero(), otherPoint = Vec3::Zero();  // world, metres
  double penetration_m = 0;                  // deepest interpenetration this tick (>= 0)
  Vec3 contactForce_N = Vec3::Zero();        // what the other parts do to the carried part
  Vec3 couplingForce_N = Vec3::Zero();       // what the hand feels of it (two-finger: at the wrist)
  Vec3 couplingTorque_Nm = Vec3::Zero();
  int contacts = 0, active = 0;              // rows within the margin, and those pushing
  int substeps = 0, queried = 0;
  bool lagging = false;                      // the hand outran the coupling's sub-steps
  bool saturated = false;                    // the coupling's wrench was cut to the device's limits
  double passivityEnergy_J = 0;              // the coupling's ports, translational and rotational
  double rotationalPassivityEnergy_J = 0;

  bool interference() const noexcept { return clearanceExact && clearance_m < 0; }
};

}  // namespace hg::contact
