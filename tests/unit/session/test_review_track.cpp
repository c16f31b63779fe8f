// The review track: frames at the viewer's rate plus every state change, each moving part's
// pose at any time (exact at put-down and at the end), every event, and each part's last
// recorded model, from the description or from a model swap.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hapticgrasp/session/mcap_reader.hpp"
#include "hapticgrasp/session/recorder.hpp"
#include "hapticgrasp/session/review_track.hpp"
#include "hapticgrasp/session/tick_message.hpp"
#include "session/stepped_session.hpp"

namespace hg::session {
namespace {

namespace fs = std::filesystem;

// The bench session (grasp, lift, put-down of the cylinder) recorded, 3 s at 2 kHz, with
// two notes given out of order (lifted at 1.1 s, open hand at 0.05 s).
std::string recordBench(const std::string& name) {
  const std::string file = (test::tempDir("review") / name).string();
  test::SteppedLoop session;
  Recorder recorder(file, session.description(), session.scene);
  session.loop.record(recorder.ring());
  recorder.start();
  recorder.annotate(1.1, "lifted", "cylinder");
  recorder.annotate(0.05, "open", "");
  session.run(0, 6000, 1000);
  recorder.stop();
  return file;
}

// Every tick's time and the cylinder's pose then (the truth the track reduces).
struct Truth {
  std::vector<double> time_s;
  std::vector<grasp::PartPose> pose;
  std::size_t changes = 0;
};
Truth readTruth(const std::string& file, const grasp::PartPose& initial) {
  Truth truth;
  McapReader reader(file);
  std::uint64_t first = 0;
  grasp::PartPose pose = initial;
  servo::TickRecord r;
  reader.scan([&](const McapMessageView& m) {
    if (reader.channels().at(m.channel).topic != kTickTopic || !decodeTick(m.data, r)) return;
    if (truth.time_s.empty()) first = m.logTime_ns;
    for (int k = 0; k < std::min(r.movingCount, servo::TickRecord::kMaxMoving); ++k)
      if (r.movingPart[k] == 0) pose = r.movingPose[k];
    truth.changes += r.events != 0 || r.state != r.stateBefore;
    truth.time_s.push_back(1e-9 * static_cast<double>(m.logTime_ns - first));
    truth.pose.push_back(pose);
  });
  return truth;
}

TEST(ReviewTrack, FramesAtTheViewersRatePlusEveryChange) {
  const std::string file = recordBench("frames.mcap");
  const ReviewTrack track = readReviewTrack(file, 60);
  const Truth truth = readTruth(file, track.info.description.parts[0].initialPose);
  const double duration = track.frames.back().time_s;
  EXPECT_EQ(duration, truth.time_s.back());  // the last tick is a frame
  EXPECT_EQ(track.events.size(), truth.changes);
  EXPECT_GE(track.frames.size(), static_cast<std::size_t>(duration * 60));
  EXPECT_LE(track.frames.size(), static_cast<std::size_t>(duration * 60) + truth.changes + 2);
  for (std::size_t i = 1; i < track.frames.size(); ++i) ASSERT_GT(track.frames[i].time_s, track.frames[i - 1].time_s);
  for (const SessionEvent& e : track.events)  // each change has a frame of its own
    EXPECT_EQ(track.frames[track.frameAt(e.time_s)].time_s, e.time_s);
  EXPECT_EQ(track.frameAt(-1), 0u);
  EXPECT_EQ(track.frameAt(1e9), track.frames.size() - 1);
  const ReviewFrame& f = track.frames[track.frameAt(1.1)];  // lifted
  EXPECT_EQ(f.state, grasp::GraspState::Manipulate);
  EXPECT_EQ(f.graspedPart, 0);
  EXPECT_GT(f.force_N[0].norm(), 0.0);
  EXPECT_GT(f.fingertip_m[0].x(), f.fingertip_m[1].x());  // index at +x, thumb at -x
}

TEST(ReviewTrack, APartsPoseIsExactAtPutDownAndCloseWhileCarried) {
  const std::string file = recordBench("poses.mcap");
  const ReviewTrack track = readReviewTrack(file, 60);
  const grasp::PartPose initial = track.info.description.parts[0].initialPose;
  const Truth truth = readTruth(file, initial);
  ASSERT_EQ(track.movedParts(), std::vector<int>{0});
  EXPECT_EQ(track.poseAt(0, -1).position, initial.position);
  EXPECT_EQ(track.poseAt(0, 0.05).position, initial.position);  // not yet touched
  EXPECT_EQ(track.poseAt(0, 1e9).position, truth.pose.back().position);  // bit for bit
  EXPECT_EQ(track.poseAt(0, 1e9).rotation, truth.pose.back().rotation);
  double worst = 0;  // while carried, within a frame's travel (lift: 50 mm in 0.4 s; put-down in 0.3 s)
  for (std::size_t k = 0; k < truth.time_s.size(); k += 7)
    worst = std::max(worst, (track.poseAt(0, truth.time_s[k]).position - truth.pose[k].position).norm());
  std::printf("largest pose lag between frames: %.3f mm\n", 1e3 * worst);
  EXPECT_GT(worst, 0.0);
  EXPECT_LT(worst, 0.25 / 60 + 1e-9);  // 0.25 m/s at most, a 60 Hz frame
}

TEST(ReviewTrack, NotesComeInTimeOrderWithTheHandThen) {
  const ReviewTrack track = readReviewTrack(recordBench("notes.mcap"), 60);
  ASSERT_EQ(track.notes.size(), 2u);
  EXPECT_EQ(track.notes[0].note.text, "open");
  EXPECT_EQ(track.notes[1].note.text, "lifted");
  EXPECT_EQ(track.notes[1].note.part, "cylinder");
  for (const ReviewNote& n : track.notes) {  // the fingertips' midpoint, within a frame's travel
    const ReviewFrame& f = track.frames[track.frameAt(n.note.time_s)];
    EXPECT_LT((n.hand_m - 0.5 * (f.fingertip_m[0] + f.fingertip_m[1])).norm(), 0.25 / 60);
    EXPECT_GT(n.hand_m.norm(), 0.0);
  }
  // Lifted: the hand 50 mm higher than when it was open.
  EXPECT_GT(track.notes[1].hand_m.z() - track.notes[0].hand_m.z(), 0.04);
}

TEST(ReviewTrack, TakesEachPartsLastModelFromTheModelSwaps) {
  const std::string file = (test::tempDir("review") / "swapped.mcap").string();
  test::recordSwappedSession(file);
  const ReviewTrack track = readReviewTrack(file, 30);
  EXPECT_TRUE(track.info.description.parts[0].coarse);  // the session began on the stand-in
  ASSERT_EQ(track.models.size(), 1u);
  EXPECT_FALSE(track.models[0].coarse);
  EXPECT_FALSE(track.models[0].brep.empty());
  EXPECT_EQ(track.models[0].faces, servo::benchScene()->part(0).model->faces().Extent());
}

TEST(ReviewTrack, ATruncatedRecordingGivesWhatItHolds) {
  const std::string file = recordBench("whole.mcap");
  const ReviewTrack whole = readReviewTrack(file, 60);
  const std::string cut = (test::tempDir("review") / "cut.mcap").string();
  fs::copy_file(file, cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(file) * 2 / 3);
  const ReviewTrack part = readReviewTrack(cut, 60);
  EXPECT_FALSE(part.info.complete);
  EXPECT_LT(part.frames.size(), whole.frames.size());
  EXPECT_GT(part.frames.size(), 0u);
}

TEST(ReviewTrack, AFileThatIsNotARecordingGetsAClearError) {
  const fs::path file = test::tempDir("review") / "not.mcap";
  { std::ofstream(file) << "hello"; }
  EXPECT_THROW(readReviewTrack(file.string()), std::runtime_error);
  EXPECT_THROW(readReviewTrack(file.string(), 0), std::invalid_argument);
}

}  // namespace
}  // namespace hg::session
