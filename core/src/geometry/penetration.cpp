#include "hapticgrasp/geometry/penetration.hpp"

namespace hg::geometry {

const char* toString(Feature feature) {
  switch (feature) {
    case Feature::Face: return "face";
    case Feature::Edge: return "edge";
    case Feature::Vertex: return "vertex";
    default: return "none";
  }
}

bool PenetrationModel::queryFeature(const Vec3&, Feature, int, double&, double&, Penetration&) const noexcept {
  return false;
}

Penetration PenetrationModel::track(const Vec3& x, QueryState& state, double hysteresis_m) const noexcept {
  const Penetration closest = query(x, state);
  if (!closest.inside) {
    state.tracked = Feature::None;
    state.trackedIndex = 0;
    return closest;
  }
  if (state.tracked != Feature::None &&
      !(state.tracked == closest.feature && state.trackedIndex == closest.featureIndex)) {
    Penetration held;
    double u = state.tu, v = state.tv;
    // Inside, the closest feature has the smallest depth; the held one may be deeper by
    // up to the hysteresis before the contact moves to the closer feature.
    if (queryFeature(x, state.tracked, state.trackedIndex, u, v, held) &&
        held.depth <= closest.depth + hysteresis_m) {
      held.inside = true;
      state.tu = u;
      state.tv = v;
      return held;
    }
  }
  state.tracked = closest.feature;
  state.trackedIndex = closest.featureIndex;
  state.tu = state.u;
  state.tv = state.v;
  return closest;
}

}  // namespace hg::geometry
