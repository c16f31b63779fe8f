#include "hapticgrasp/contact/contact_query.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hg::contact {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The angle of the rotation that takes `from` to `to`, radians.
double angleBetween(const Mat3& from, const Mat3& to) noexcept {
  const double c = 0.5 * ((to * from.transpose()).trace() - 1);
  return std::acos(std::clamp(c, -1.0, 1.0));
}

}  // namespace

ContactQuery::ContactQuery(ContactModelPtr held, const ContactQueryConfig& config)
    : held_(std::move(held)), config_(config) {
  if (config.maxPoints <= 0 || config.maxNearby <= 0 || config.maxContacts <= 0)
    throw std::invalid_argument("contact query: capacities must be positive");
  if (held_ && held_->shell().size() > static_cast<std::size_t>(config.maxPoints))
    throw std::invalid_argument("contact query: the carried part's shell exceeds maxPoints");
  pairs_.resize(config.maxNearby);
  for (Pair& p : pairs_) {
    p.held.bound.resize(config.maxPoints);
    p.held.answer.resize(config.maxPoints);
    p.other.bound.resize(config.maxPoints);
    p.other.answer.resize(config.maxPoints);
  }
  nearby_.resize(config.maxNearby);
  contacts_.resize(config.maxContacts);
}

void ContactQuery::reset() noexcept {
  for (Pair& p : pairs_) p.part = -1;
  havePose_ = false;
}

bool ContactQuery::rebind(ContactModelPtr held) noexcept {
  if (!held || held->shell().size() > static_cast<std::size_t>(config_.maxPoints)) return false;
  held_ = std::move(held);
  reset();
  letThroughCount_ = 0;
  return true;
}

void ContactQuery::letThrough(std::span<const int> parts) noexcept {
  letThroughCount_ = std::min(parts.size(), letThrough_.size());
  std::copy_n(parts.begin(), letThroughCount_, letThrough_.begin());
}

ContactQuery::Pair* ContactQuery::pairFor(int part, const ContactScene& scene) noexcept {
  Pair* pair = nullptr;
  for (Pair& p : pairs_)
    if (p.part == part) {
      if (p.revision == scene.revision(part)) return &p;
      pair = &p;  // the part was moved: start its pair afresh
      break;
    }
  // Else a pair whose part is no longer near.
  for (Pair& p : pairs_) {
    if (pair) break;
    if (p.part < 0 || std::find(nearby_.begin(), nearby_.end(), p.part) == nearby_.end()) pair = &p;
  }
  if (!pair) return nullptr;
  const std::size_t edges = scene.body(part).model->sharpEdges().size();
  if (edges > pair->other.bound.size()) return nullptr;  // larger than its capacity: counted as overflow
  Pair& p = *pair;
  p.part = part;
  p.revision = scene.revision(part);
  p.cursor = 0;
  p.moved = p.turned = 0;
  for (SideCache* side : {&p.held, &p.other}) {
    std::fill(side->bound.begin(), side->bound.end(), PointBound{});
    for (PointAnswer& a : side->answer) a.plane = false, a.state.reset();
    side->minLower = -std::numeric_limits<double>::infinity();
    side->passMoved = side->passTurned = 0;
  }
  return &p;
}

// The clearance so far: the smallest gap among the near points answered. Where a face
// rests on a face, its edge points tie with its face points; an edge point names only one
// of its two faces (maybe the side), so a face point wins a tie: the faces named are the
// ones that meet.
void ContactQuery::offer(const Contact& c, const Vec3& otherPoint) noexcept {
  constexpr double kTie_m = 1e-9;
  const bool edge = c.heldEdge || c.otherEdge;
  const bool nearer = !clearance_.exact || c.gap < clearance_.distance_m - kTie_m;
  const bool tieOffFace = clearance_.exact && clearanceOnEdge_ && !edge && c.gap < clearance_.distance_m + kTie_m;
  if (!nearer && !tieOffFace) return;
  clearance_ = {c.gap, c.part, c.heldFace, c.otherFace, c.point, otherPoint, true};
  clearanceOnEdge_ = edge;
}

// Answers one side of a pair: each point's bound, tangent plane or exact query; the whole
// side at once while its smallest bound keeps it beyond range.
void ContactQuery::answer(const Side& side, Pair& pair, double range, double margin) noexcept {
  SideCache& cache = *side.cache;
  const double maxReach = side.heldPoints ? held_->radius() : side.reach;
  const double lowerAll = cache.minLower - (pair.moved - cache.passMoved) - (pair.turned - cache.passTurned) * maxReach;
  if (lowerAll > range) {
    farBound_ = std::min(farBound_, lowerAll);
    return;
  }
  const geometry::PenetrationModel& penetration = side.queried->penetration();
  const geometry::Aabb box = side.queried->bounds();
  const std::size_t n = side.points.size();
  double minLower = std::numeric_limits<double>::infinity();
  const std::size_t start = pair.cursor % std::max<std::size_t>(n, 1);
  for (std::size_t step = 0; step < n; ++step) {
    const std::size_t k = (start + step) % n;
    const ShellPoint& point = side.points[k];
    PointBound& b = cache.bound[k];
    const double drift =
        (pair.moved - b.moved0) + (pair.turned - b.turned0) * (side.heldPoints ? point.reach : side.reach);
    if (b.gap - drift > range) {
      minLower = std::min(minLower, b.gap - drift);
      continue;  // far: nothing to do
    }
    PointAnswer& c = cache.answer[k];
    const Vec3 x = side.rotation * point.position + side.translation;  // in the queried part's frame
    const bool stale = !c.plane || drift > config_.requery_m;
    const bool mustQuery = !c.plane || drift > config_.maxPredict_m;
    if (stale && (mustQuery || budget_ > 0)) {
      b.moved0 = pair.moved;
      b.turned0 = pair.turned;
      const double boxDistance = std::sqrt(box.squaredDistance(x));
      if (boxDistance > range) {  // its box says far enough: no exact query
        b.gap = boxDistance;
        c.plane = false;
        minLower = std::min(minLower, boxDistance);
        continue;
      }
      if (!mustQuery) --budget_;
      const geometry::Penetration q = penetration.query(x, c.state);
      ++stats_.queried;
      b.gap = -q.depth;
      c.foot = q.foot;
      c.normal = q.normal;
      c.face = q.feature == geometry::Feature::Face ? q.featureIndex : 0;
      c.plane = q.normal.allFinite() && q.normal.squaredNorm() > 0.5;
      minLower = std::min(minLower, b.gap);
      if (!c.plane || b.gap > range) continue;  // exact, and far
    } else {
      if (stale) ++stats_.deferred;
      ++stats_.predicted;
      minLower = std::min(minLower, b.gap - drift);
    }
    const double gap = c.normal.dot(x - c.foot);  // the tangent plane of the last foot
    if (gap >= margin && clearance_.exact && gap >= clearance_.distance_m) continue;  // neither a row nor the nearest
    Contact contact;
    contact.gap = gap;
    contact.part = pair.part;
    contact.key = static_cast<int>(((&pair - pairs_.data()) * 2 + (side.heldPoints ? 0 : 1)) * config_.maxPoints + k);
    const grasp::PartPose& queriedPose = *side.queriedPose;
    Vec3 otherPoint;
    if (side.heldPoints) {
      contact.point = queriedPose.pointToAbsolute(x);
      contact.normal = queriedPose.vectorToAbsolute(c.normal);
      contact.heldFace = point.face;
      contact.otherFace = c.face;
      contact.heldEdge = point.edge != 0;
      otherPoint = contact.point - gap * contact.normal;
    } else {
      // The other part's edge point x, against the carried part (queried): the carried
      // part's material point is the foot on its surface, and it must move away from x.
      contact.point = queriedPose.pointToAbsolute(x - gap * c.normal);
      contact.normal = -queriedPose.vectorToAbsolute(c.normal);
      contact.heldFace = c.face;
      contact.otherFace = point.face;
      contact.otherEdge = true;
      otherPoint = queriedPose.pointToAbsolute(x);
    }
    offer(contact, otherPoint);
    if (gap >= margin) continue;
    ++stats_.contacts;
    // Full: keep the smallest gaps, the largest kept on top of a heap (O(log n) a contact,
    // in place: no allocation).
    const auto byGap = [](const Contact& l, const Contact& r) { return l.gap < r.gap; };
    if (contactCount_ < contacts_.size()) {
      contacts_[contactCount_++] = contact;
      if (contactCount_ == contacts_.size()) std::make_heap(contacts_.begin(), contacts_.end(), byGap);
    } else if (gap < contacts_.front().gap) {
      std::pop_heap(contacts_.begin(), contacts_.end(), byGap);
      contacts_.back() = contact;
      std::push_heap(contacts_.begin(), contacts_.end(), byGap);
    }
  }
  pair.cursor = start + 1;
  cache.minLower = minLower;
  cache.passMoved = pair.moved;
  cache.passTurned = pair.turned;
  farBound_ = std::min(farBound_, minLower);
}

std::span<const Contact> ContactQuery::run(const grasp::PartPose& pose, const ContactScene& scene, int held,
                                           double margin_m) noexcept {
  stats_ = {};
  contactCount_ = 0;
  clearance_ = {};
  clearanceOnEdge_ = false;
  farBound_ = kInfinity;
  if (!held_) return {};
  shift_ = havePose_ ? (pose.pointToAbsolute(held_->centre()) - lastPose_.pointToAbsolute(held_->centre())).norm()
                     : kInfinity;
  turn_ = havePose_ ? angleBetween(lastPose_.rotation, pose.rotation) : kInfinity;
  if (!havePose_) {
    for (Pair& p : pairs_) p.part = -1;
    shift_ = turn_ = 0;  // every pair starts afresh
  }
  lastPose_ = pose;
  havePose_ = true;
  for (Pair& p : pairs_) {  // every pair counts the motion, near this run or not
    p.moved += shift_;
    p.turned += turn_;
  }
  const double range = std::max(margin_m, config_.clearanceRange_m);

  const geometry::Aabb box = pose.absoluteBounds(held_->bounds()).inflated(range);
  std::size_t total = scene.nearby(box, held, nearby_);
  std::size_t count = std::min(total, nearby_.size());
  if (letThroughCount_ > 0) {  // the parts it passes through: as if they were not near
    const auto through = lettingThrough();
    const auto kept = std::remove_if(nearby_.begin(), nearby_.begin() + static_cast<std::ptrdiff_t>(count), [&](int p) {
      return std::find(through.begin(), through.end(), p) != through.end();
    });
    const auto dropped = static_cast<std::size_t>(nearby_.begin() + static_cast<std::ptrdiff_t>(count) - kept);
    count -= dropped;
    total -= dropped;
  }
  for (std::size_t k = count; k < nearby_.size(); ++k) nearby_[k] = -1;
  stats_.nearby = static_cast<int>(total);
  stats_.overflow = static_cast<int>(total - count);
  for (std::size_t k = 0; k < count; ++k) {
    Pair* pair = pairFor(nearby_[k], scene);
    if (!pair) {
      ++stats_.overflow;
      continue;
    }
    const ContactBody& other = scene.body(pair->part);
    budget_ = config_.queryBudget;
    // The carried part's shell in the other's frame: x_o = R_o^T (R_h p + t_h - t_o).
    const Mat3 heldToOther = other.pose.rotation.transpose() * pose.rotation;
    const Vec3 heldShift = other.pose.rotation.transpose() * (pose.position - other.pose.position);
    answer({held_->shell(), &pair->held, heldToOther, heldShift, other.model.get(), &other.pose, true, 0.0}, *pair,
           range, margin_m);
    // The other's edge points, in the carried part's frame, turn with it about its centre:
    // by at most their distance from it, bounded by the two parts' centres and sizes.
    const double edgeReach =
        (other.pose.pointToAbsolute(other.model->centre()) - pose.pointToAbsolute(held_->centre())).norm() +
        other.model->radius() + range;
    answer({other.model->sharpEdges(), &pair->other, heldToOther.transpose(), -heldToOther.transpose() * heldShift,
            held_.get(), &pose, false, edgeReach},
           *pair, range, margin_m);
  }
  if (!clearance_.exact) clearance_.distance_m = farBound_;  // no point near: a bound only
  return {contacts_.data(), contactCount_};
}

}  // namespace hg::contact
