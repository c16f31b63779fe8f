#include "hapticgrasp/session/review_track.hpp"

#include <algorithm>
#include <cmath>

#include "hapticgrasp/servo/servo_loop.hpp"
#include "hapticgrasp/session/mcap_reader.hpp"
#include "hapticgrasp/session/model_swap_message.hpp"
#include "hapticgrasp/session/recorder.hpp"
#include "hapticgrasp/session/tick_message.hpp"

namespace hg::session {
namespace {

ReviewFrame frameOf(double t, const servo::TickRecord& r, const grasp::HandSample& hand) {
  ReviewFrame f;
  f.time_s = t;
  f.state = r.state;
  f.fault = r.watchdogFault != 0;
  f.graspedPart = r.graspedPart;
  f.fingertips = std::clamp(r.fingertips, 2, ReviewFrame::kMaxFingertips);
  for (int k = 0; k < ReviewFrame::kMaxFingertips; ++k) {
    f.fingertip_m[k] = hand.fingertip(k);
    f.force_N[k] = r.sent.fingertipForce(k);
  }
  f.wrist_m = hand.wrist;
  f.grasp_N = r.sent.f_grasp;
  return f;
}

// The pose keys: a part gets one when it starts moving, at every frame while it moves,
// when it stops (its put-down pose, exactly), and when a reset puts it back.
class PoseKeys {
 public:
  PoseKeys(ReviewTrack& track) : track_(track), last_(track.info.description.parts.size()) {
    track_.poses.resize(last_.size());
    for (std::size_t i = 0; i < last_.size(); ++i) last_[i] = track.info.description.parts[i].initialPose;
  }
  void update(double t, const servo::TickRecord& r, bool frame) {
    if ((r.commands & servo::kCommandReset) || (r.events & servo::kWatchdogTrip)) {
      for (std::size_t i = 0; i < last_.size(); ++i) {
        if (track_.poses[i].empty()) continue;
        last_[i] = track_.info.description.parts[i].initialPose;
        track_.poses[i].push_back({t, last_[i]});
      }
      moving_.clear();
    }
    const int n = std::min(r.movingCount, servo::TickRecord::kMaxMoving);
    std::vector<int>& now = now_;  // reused: one allocation per file, not per tick
    now.clear();
    for (int k = 0; k < n; ++k) {
      const int part = r.movingPart[k];
      if (part < 0 || static_cast<std::size_t>(part) >= last_.size()) continue;
      now.push_back(part);
      last_[static_cast<std::size_t>(part)] = r.movingPose[k];
      const bool starts = std::find(moving_.begin(), moving_.end(), part) == moving_.end();
      if (frame || starts) track_.poses[static_cast<std::size_t>(part)].push_back({t, r.movingPose[k]});
    }
    for (const int part : moving_)
      if (std::find(now.begin(), now.end(), part) == now.end())
        track_.poses[static_cast<std::size_t>(part)].push_back({t, last_[static_cast<std::size_t>(part)]});
    moving_.swap(now);
  }
  // The last tick: the parts still moving get their pose then, so the end is exact too.
  void finish(double t) {
    for (const int part : moving_) {
      std::vector<PoseKey>& keys = track_.poses[static_cast<std::size_t>(part)];
      if (keys.empty() || keys.back().time_s < t) keys.push_back({t, last_[static_cast<std::size_t>(part)]});
    }
  }

 private:
  ReviewTrack& track_;
  std::vector<grasp::PartPose> last_;
  std::vector<int> moving_, now_;
};

double seconds(std::uint64_t t, std::uint64_t origin) { return t > origin ? 1e-9 * static_cast<double>(t - origin) : 0.0; }

}  // namespace

std::size_t ReviewTrack::frameAt(double t) const {
  const auto after = std::upper_bound(frames.begin(), frames.end(), t,
                                      [](double time, const ReviewFrame& f) { return time < f.time_s; });
  return after == frames.begin() ? 0 : static_cast<std::size_t>(after - frames.begin()) - 1;
}

grasp::PartPose ReviewTrack::poseAt(std::size_t part, double t) const {
  const std::vector<PoseKey>& keys = poses.at(part);
  const auto after =
      std::upper_bound(keys.begin(), keys.end(), t, [](double time, const PoseKey& k) { return time < k.time_s; });
  if (after == keys.begin()) return info.description.parts.at(part).initialPose;
  return std::prev(after)->pose;
}

std::vector<int> ReviewTrack::movedParts() const {
  std::vector<int> moved;
  for (std::size_t i = 0; i < poses.size(); ++i)
    if (!poses[i].empty()) moved.push_back(static_cast<int>(i));
  return moved;
}

ReviewTrack readReviewTrack(const std::string& path, double frameRate_hz) {
  if (!(frameRate_hz > 0 && frameRate_hz <= 10000)) throw std::invalid_argument("review: frame rate out of (0, 10000] Hz");
  ReviewTrack track;
  track.info = readRecordingInfo(path);
  McapReader reader(path);
  bool described = false;
  PoseKeys keys(track);
  servo::TickRecord r;
  grasp::HandSample hand;
  double nextFrame = 0;
  ReviewFrame last;  // the last tick when it is not a frame: the track ends where the recording does
  bool lastPending = false;
  for (const Annotation& a : track.info.annotations) track.notes.push_back({a, Vec3::Zero()});
  std::stable_sort(track.notes.begin(), track.notes.end(),
                   [](const ReviewNote& a, const ReviewNote& b) { return a.note.time_s < b.note.time_s; });
  std::size_t nextNote = 0;
  reader.scan(
      [&](const McapMessageView& m) {
        if (!described) {  // the description and its attachments precede every message
          track.models = readDescription(reader, /*withShapes=*/true).parts;
          described = true;
        }
        const auto channel = reader.channels().find(m.channel);
        if (channel == reader.channels().end()) return;
        if (channel->second.topic == kModelTopic) {
          try {
            ModelSwap swap = decodeModelSwap(m.data);
            if (swap.part >= 0 && static_cast<std::size_t>(swap.part) < track.models.size())
              track.models[static_cast<std::size_t>(swap.part)] = std::move(swap.model);
          } catch (const SessionError& e) {  // that part keeps its earlier model
            track.info.warnings.push_back(e.what());
          }
          return;
        }
        if (channel->second.topic != kTickTopic || !decodeTick(m.data, r)) return;
        const double t = seconds(m.logTime_ns, track.info.firstTime_ns);
        if (r.freshSample) hand = r.sample.hand;
        for (; nextNote < track.notes.size() && track.notes[nextNote].note.time_s <= t; ++nextNote)
          track.notes[nextNote].hand_m = 0.5 * (hand.fingertip(0) + hand.fingertip(1));
        const bool changed = r.events != 0 || r.state != r.stateBefore;
        const bool frame = t >= nextFrame || changed || track.frames.empty();
        keys.update(t, r, frame);
        if (changed) track.events.push_back({t, servo::eventsText(r.events), r.stateBefore, r.state, r.events});
        lastPending = !frame;
        if (!frame) {
          last = frameOf(t, r, hand);
          return;
        }
        track.frames.push_back(frameOf(t, r, hand));
        nextFrame = t + 1.0 / frameRate_hz;
      },
      /*attachmentData=*/true);
  if (track.frames.empty()) throw SessionError(path + ": no ticks recorded");
  if (lastPending) {
    track.frames.push_back(last);
    keys.finish(last.time_s);
  }
  return track;
}

}  // namespace hg::session
