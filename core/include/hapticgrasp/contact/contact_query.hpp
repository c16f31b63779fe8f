#pragma once
// The narrow phase between a carried part and the parts around it, from the exact B-rep:
// the carried part's shell points against each nearby part's penetration back end, and
// each nearby part's sharp-edge points against the carried part's, so that edge-on-face
// and edge-on-edge contacts are found both ways. Gives the contacts within a margin (the
// constraint solver's rows) and the clearance: the smallest distance from the carried
// part to any other, and between which faces.
//
// Coherence makes it cheap. Each point remembers its last exact answer (the gap, the foot
// and the normal there) and how far it has drifted relative to the other part since
// (|Δc| + |Δθ| reach per move). A point whose gap minus drift exceeds the range is far and
// costs a subtraction. A near point is answered by the tangent plane of its last foot while
// its drift stays below `requery_m` (exact on planes; off by drift²/2R on a surface of
// radius R), and queried exactly again after that: at rest in contact nothing is queried.
// Re-queries of points that are merely stale are capped per run (`queryBudget`, taken in
// turn, so the cap spreads them over ticks); a point new in range, or one that drifted
// farther than `maxPredict_m` (where its plane, extended past the face's border into a
// corner, could be off by as much), is always queried. Before an exact query, the other part's own box (its
// frame) gives a distance bound in a few flops.
//
// Everything is preallocated at construction: run() allocates nothing, locks nothing,
// throws nothing (servo thread).
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "hapticgrasp/contact/contact_scene.hpp"
#include "hapticgrasp/geometry/penetration.hpp"

namespace hg::contact {

// One point of contact, or of near contact, between the carried part and another.
struct Contact {
  Vec3 point = Vec3::Zero();   // world: the carried part's material point there
  Vec3 normal = Vec3::Zero();  // world, unit: the way the carried part must move to separate
  double gap = 0;              // signed distance along normal, m; < 0: interpenetrating
  int part = -1;               // the other part (its index in the ContactScene)
  int heldFace = 0;            // the carried part's face there (1-based; 0: an edge or vertex foot)
  int otherFace = 0;           // the other part's face there (1-based; 0: an edge or vertex foot)
  bool otherEdge = false;      // found by the other part's sharp-edge point (else the carried part's point)
  bool heldEdge = false;       // the carried part's point lies on one of its sharp edges
  int key = 0;                 // which point of which pair: stable while the pair stays near
};

// The smallest distance between the carried part and any other, over the points queried
// (within range); `exact` is false when no point was within range and distance_m is only
// a lower bound (infinite: no part near at all).
struct Clearance {
  double distance_m = std::numeric_limits<double>::infinity();  // < 0: interference, by that depth
  int part = -1;
  int heldFace = 0, otherFace = 0;
  Vec3 heldPoint = Vec3::Zero(), otherPoint = Vec3::Zero();  // world, the two ends of it
  bool exact = false;
};

struct ContactQueryConfig {
  int maxPoints = 2048;         // the largest shell (carried part) or sharp-edge set (others) it takes
  int maxNearby = 8;            // parts answered at once; more are counted in overflow()
  int maxContacts = 512;        // rows handed to the solver (the smallest gaps first when more)
  double clearanceRange_m = 0;  // points within this distance are queried too, for the clearance
  double requery_m = 2e-5;      // drift after which a near point is queried exactly again
  double maxPredict_m = 5e-5;   // drift after which it is queried whatever the budget
  int queryBudget = 48;         // re-queries of stale points a run, per pair (new ones are not capped)
};

struct ContactQueryStats {
  int queried = 0;    // exact queries this run
  int nearby = 0;     // parts whose boxes overlapped
  int overflow = 0;   // nearby parts beyond maxNearby (not answered: say so)
  int contacts = 0;   // within the margin (before the maxContacts cut)
  int predicted = 0;  // near points answered by their last tangent plane
  int deferred = 0;   // stale points left to their tangent plane by the budget
};

class ContactQuery {
 public:
  // `held` may be none: the query is unbound (run() finds nothing) until rebind().
  // Throws std::invalid_argument for a non-positive capacity or a shell larger than it.
  // Every cache is sized for maxPoints, so that rebind() can take any part that fits.
  ContactQuery(ContactModelPtr held, const ContactQueryConfig& config = {});

  // The contacts of the carried part `held` (its index in `scene`, or -1 when it is not one
  // of the scene's parts) at `pose`, within `margin_m`. Valid until the next run().
  std::span<const Contact> run(const grasp::PartPose& pose, const ContactScene& scene, int held,
                               double margin_m) noexcept;
  // Forget every bound and warm start (a teleported part, a new scene).
  void reset() noexcept;
  // Another carried part, in no contact history. False (and nothing changes) when its
  // shell exceeds maxPoints. No allocation: the caches were sized for maxPoints.
  bool rebind(ContactModelPtr held) noexcept;
  // Parts this query leaves out (at most kMaxLetThrough; the rest of `parts` is dropped):
  // the carried part passes through them. Replaces the previous list; rebind() clears it.
  static constexpr int kMaxLetThrough = 16;
  void letThrough(std::span<const int> parts) noexcept;
  std::span<const int> lettingThrough() const noexcept { return {letThrough_.data(), letThroughCount_}; }

  std::span<const Contact> contacts() const noexcept { return {contacts_.data(), contactCount_}; }  // the last run's
  const Clearance& clearance() const noexcept { return clearance_; }
  const ContactQueryStats& stats() const noexcept { return stats_; }
  const ContactModel& held() const noexcept { return *held_; }  // bound only
  bool bound() const noexcept { return held_ != nullptr; }
  // Contact keys lie in [0, keyCount()).
  int keyCount() const noexcept { return 2 * config_.maxNearby * config_.maxPoints; }

 private:
  // What one point knows about the other part of its pair, split hot from cold so that a
  // pass over far points touches 24 bytes a point. Its last exact gap (or a lower bound,
  // !plane) and the pair's accumulated motion then: its drift since is
  // (moved - moved0) + (turned - turned0) reach, counted without visiting it.
  struct PointBound {
    double gap = -std::numeric_limits<double>::infinity();
    double moved0 = 0, turned0 = 0;
  };
  // The rest of its last answer, in the frame it is queried in (the other part's for the
  // carried part's points, the carried part's for the other's edge points).
  struct PointAnswer {
    Vec3 foot = Vec3::Zero(), normal = Vec3::Zero();
    int face = 0;
    bool plane = false;  // foot and normal hold
    geometry::QueryState state;
  };
  // One side of a pair's cache, and the smallest lower bound of its points at its last
  // pass: while that, less the motion since, stays beyond range, the side is skipped whole.
  struct SideCache {
    std::vector<PointBound> bound;
    std::vector<PointAnswer> answer;
    double minLower = -std::numeric_limits<double>::infinity();
    double passMoved = 0, passTurned = 0;
  };
  // One nearby part: the cache of the carried part's shell against it, and of its sharp
  // edges against the carried part.
  struct Pair {
    int part = -1;
    std::uint64_t revision = 0;    // the scene's revision it was filled at
    double moved = 0, turned = 0;  // the carried part's motion since the pair began: sum |Δc|, sum |Δθ|
    SideCache held, other;
    std::size_t cursor = 0;  // where the budgeted re-queries start next run
  };
  // One side of a pair: the points, the frame change into the queried part, and that part.
  struct Side {
    std::span<const ShellPoint> points;
    SideCache* cache;
    Mat3 rotation;  // points' frame -> queried part's frame
    Vec3 translation;
    const ContactModel* queried;
    const grasp::PartPose* queriedPose;  // world pose of the queried part
    bool heldPoints;                     // the carried part's shell (else the other's edges)
    double reach;                        // the other's edges: their largest distance from the carried part's centre
  };
  Pair* pairFor(int part, const ContactScene& scene) noexcept;
  void answer(const Side& side, Pair& pair, double range, double margin) noexcept;
  void offer(const Contact& c, const Vec3& otherPoint) noexcept;

  ContactModelPtr held_;
  ContactQueryConfig config_;
  std::vector<Pair> pairs_;
  std::vector<int> nearby_;
  std::array<int, kMaxLetThrough> letThrough_{};
  std::size_t letThroughCount_ = 0;
  std::vector<Contact> contacts_;
  std::size_t contactCount_ = 0;
  Clearance clearance_;
  bool clearanceOnEdge_ = false;  // the clearance's pair of points involves an edge point
  ContactQueryStats stats_;
  grasp::PartPose lastPose_;
  bool havePose_ = false;
  double shift_ = 0, turn_ = 0;  // this run's move of the carried part: |Δc| (m), |Δθ| (rad)
  int budget_ = 0;               // re-queries left for the pair being answered
  double farBound_ = 0;          // the smallest lower bound of the points not near
};

}  // namespace hg::contact
