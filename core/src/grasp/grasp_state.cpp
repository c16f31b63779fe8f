#include "hapticgrasp/grasp/grasp_state.hpp"

namespace hg::grasp {

const char* toString(GraspState state) {
  switch (state) {
    case GraspState::Free: return "FREE";
    case GraspState::IndexContact: return "INDEX CONTACT";
    case GraspState::ThumbContact: return "THUMB CONTACT";
    case GraspState::Grasp: return "GRASP";
    case GraspState::Manipulate: return "MANIPULATE";
  }
  return "?";
}

const char* eventName(GraspEvent event) {
  switch (event) {
    case kIndexContact: return "index contact";
    case kIndexDetach: return "index detach";
    case kThumbContact: return "thumb contact";
    case kThumbDetach: return "thumb detach";
    case kGrasp: return "grasp";
    case kLift: return "lift";
    case kRelease: return "release";
    case kReturn: return "return";
  }
  return "?";
}

}  // namespace hg::grasp
