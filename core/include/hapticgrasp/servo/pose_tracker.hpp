#pragma once
// Every part's pose on the reader's side of the servo loop (the GUI, a recorder, a bench),
// rebuilt from snapshots that carry only what moves: the parts held or carried this tick,
// and the log of parts put down or reset (ServoSnapshot::moving, moveLog). A reader that
// polls at 30-60 Hz misses nothing unless more than kMoveLog parts stopped moving between
// two of its reads (it is then told, and may ask the engine after stop()).
#include <cstdint>
#include <span>
#include <vector>

#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"

namespace hg::servo {

class PoseTracker {
 public:
  PoseTracker() = default;
  explicit PoseTracker(std::vector<grasp::PartPose> initial) : initial_(initial), poses_(std::move(initial)) {}

  // Brings every pose up to `snapshot`. Returns false when put-downs were lost (the log
  // wrapped since the previous update); the poses of the parts moving now are right anyway.
  bool update(const ServoSnapshot& snapshot) noexcept;

  std::span<const grasp::PartPose> poses() const noexcept { return poses_; }
  const grasp::PartPose& pose(std::size_t part) const noexcept { return poses_[part]; }
  // A new starting point (a restart with the parts where the document has them).
  void reset(std::vector<grasp::PartPose> initial);

 private:
  void apply(const PartPlacement& p) noexcept;

  std::vector<grasp::PartPose> initial_, poses_;
  std::uint64_t seen_ = 0;  // moveCount at the previous update
};

}  // namespace hg::servo
