#pragma once
// Penetration of a fingertip into a part: P_o(x) of the first paper's eqs 4-5, with what a
// contact law and a god-object proxy need besides. One interface, several back ends that
// trade speed for accuracy (reference, exact, mesh, field, analytic).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "hapticgrasp/math/types.hpp"

namespace hg::geometry {

// The kind of B-rep feature the foot point lies on.
enum class Feature : std::uint8_t { None, Face, Edge, Vertex };
const char* toString(Feature feature);

// One answer for a point x in the part's frame (metres).
struct Penetration {
  bool inside = false;         // x lies inside the solid
  double depth = 0;            // signed distance to the surface: > 0 inside, < 0 outside
  Vec3 vector = Vec3::Zero();  // p = x - foot; inside, the reaction force acts along -p
  Vec3 foot = Vec3::Zero();    // closest point of the surface
  Vec3 normal = Vec3::Zero();  // outward unit normal at the foot
  Feature feature = Feature::None;
  int featureIndex = 0;        // 1-based index into the part's faces/edges/vertices; 0 = none
  // The exact back end's accounting: how many patches of faces or pieces of edges this
  // answer needed the slower exhaustive search for (a point farther from a curved patch
  // than its curvature lets Newton guarantee the foot), and whether even that search
  // left some possibility open (false: the answer may be off; never silently).
  std::uint8_t fallbacks = 0;
  bool certain = true;
  double distance() const { return depth < 0 ? -depth : depth; }
};

// Where a feature's projection ended last tick: the next one starts there.
struct WarmStart {
  Feature feature = Feature::None;
  int index = 0;
  int piece = -1;       // the patch of a face or piece of an edge searched; -1: the whole
  double u = 0, v = 0;  // face: u, v; edge: u
};

// The exact back end's last evaluation of a freeform face near a fingertip's foot: the
// surface's point and derivatives at (u, v), so that the next tick's first Newton step
// costs no evaluation.
struct SurfaceJetState {
  int face = 0;    // 1-based; 0 = none
  int piece = -1;  // its patch
  double u = 0, v = 0;
  double values[18] = {};  // point, S_u, S_v, S_uu, S_vv, S_uv
};

// The mesh back end's winding-number sign at the last point it answered. No surface lies
// within `distance` of `x`: a fingertip that moves to x' with |x' - x| < distance +
// distance' stays inside the two balls free of surface, crosses none, and is enclosed as x
// was. `model` names the back end that wrote it (0: none), so that another's is not taken.
struct EnclosureState {
  std::uint64_t model = 0;
  Vec3 x = Vec3::Zero();
  double distance = 0;
  bool inside = false;
};

// Small mutable state of one fingertip, kept by the caller from tick to tick: the warm
// starts of the next query and the feature tracked while in contact. Plain data, no heap.
struct QueryState {
  Feature feature = Feature::None;  // closest feature last tick
  int index = 0;
  int piece = -1;                   // its patch or piece
  double u = 0, v = 0;              // its parameters (face: u, v; edge: u)
  // The other features examined last tick (a part's neighbours of the foot are examined
  // every tick; on freeform faces a cold start costs 10x a warm one).
  static constexpr int kNeighbours = 6;
  WarmStart neighbours[kNeighbours];
  SurfaceJetState jet;
  EnclosureState enclosure;
  Feature tracked = Feature::None;  // feature held while in contact (hysteresis)
  int trackedIndex = 0;
  double tu = 0, tv = 0;
  void reset() { *this = QueryState{}; }
};

class PenetrationModel {
 public:
  virtual ~PenetrationModel() = default;

  // Short back-end name ("exact", "mesh"...) and its accuracy setting ("deflection 0.01 mm").
  virtual std::string_view name() const noexcept = 0;
  virtual std::string setting() const = 0;
  // Bytes held by this back end's own data (not the shared PartModel).
  virtual std::size_t memoryBytes() const noexcept = 0;
  // Whether query() may run on the servo thread: no heap allocation, no lock, no throw.
  virtual bool realTimeSafe() const noexcept { return true; }

  // The closest surface point to x and the sign, from scratch or warm-started by `state`.
  virtual Penetration query(const Vec3& x, QueryState& state) const noexcept = 0;

  // Contact tracking: while x stays inside, keep answering with the feature it entered
  // through, unless another feature is closer by more than `hysteresis_m`. On a medial
  // axis (a cylinder rim's bisector, a hole's axis) the raw closest point jumps between
  // equally valid feet; a haptic force must not flip with it.
  Penetration track(const Vec3& x, QueryState& state, double hysteresis_m) const noexcept;

  // x measured against one named feature only (a god-object proxy holds the face it
  // entered through): queryFeature below, made public. u, v: warm start in, result out.
  // out.inside is left true; its depth is the distance to that feature's foot.
  bool againstFeature(const Vec3& x, Feature feature, int index, double& u, double& v,
                      Penetration& out) const noexcept {
    return queryFeature(x, feature, index, u, v, out);
  }

 protected:
  // x measured against one feature only: false when x does not project into it (or the
  // back end names no stable features). out.inside is set by the caller.
  virtual bool queryFeature(const Vec3& x, Feature feature, int index, double& u, double& v,
                            Penetration& out) const noexcept;
};

}  // namespace hg::geometry
