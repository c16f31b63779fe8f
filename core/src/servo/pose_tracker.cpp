#include "hapticgrasp/servo/pose_tracker.hpp"

#include <algorithm>

namespace hg::servo {

void PoseTracker::apply(const PartPlacement& p) noexcept {
  if (p.part < 0) {
    std::copy(initial_.begin(), initial_.end(), poses_.begin());
  } else if (static_cast<std::size_t>(p.part) < poses_.size()) {
    poses_[static_cast<std::size_t>(p.part)] = p.pose;
  }
}

bool PoseTracker::update(const ServoSnapshot& s) noexcept {
  bool complete = true;
  if (s.moveCount > seen_) {
    const std::uint64_t oldest = s.moveCount > ServoSnapshot::kMoveLog ? s.moveCount - ServoSnapshot::kMoveLog : 0;
    complete = seen_ >= oldest;
    for (std::uint64_t i = std::max(seen_, oldest); i < s.moveCount; ++i) apply(s.moveLog[i % ServoSnapshot::kMoveLog]);
  }
  seen_ = s.moveCount;
  for (int k = 0; k < s.movingCount; ++k) apply(s.moving[k]);
  return complete;
}

void PoseTracker::reset(std::vector<grasp::PartPose> initial) {
  initial_ = initial;
  poses_ = std::move(initial);
  seen_ = 0;
}

}  // namespace hg::servo
