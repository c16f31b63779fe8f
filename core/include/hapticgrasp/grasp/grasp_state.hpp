#pragma once
// The five states of the first paper's Fig. 3 and the events a tick can raise (each one
// a sound in the paper's audio feedback).
#include <cstdint>

namespace hg::grasp {

enum class GraspState : std::uint8_t { Free, IndexContact, ThumbContact, Grasp, Manipulate };
const char* toString(GraspState state);  // "FREE", "INDEX CONTACT", ...

// Bits of GraspOutput::events.
enum GraspEvent : std::uint32_t {
  kIndexContact = 1u << 0,  // IC: the index fingertip entered a part
  kIndexDetach = 1u << 1,   // ID: it left
  kThumbContact = 1u << 2,  // TC
  kThumbDetach = 1u << 3,   // TD
  kGrasp = 1u << 4,         // both fingertips on one part: GRASP
  kLift = 1u << 5,          // the springs carry the weight: MANIPULATE (eq 29, corrected)
  kRelease = 1u << 6,       // the fingertips separated past the hysteresis (eq 28)
  kReturn = 1u << 7,        // released from GRASP: the part went back where it was
};
constexpr int kEventCount = 8;
const char* eventName(GraspEvent event);  // "index contact", ...

}  // namespace hg::grasp
