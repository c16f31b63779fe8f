// Replay re-simulates a recording through the same engine and stages: on the build that
// recorded it the result is bit-identical, for both grasp methods, through watchdog faults
// and through the model swaps of a scene built behind the servo; a changed recording is
// caught.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/geometry/sample_parts.hpp"
#include "hapticgrasp/servo/servo_bench.hpp"
#include "hapticgrasp/session/mcap_reader.hpp"
#include "hapticgrasp/session/model_swap_message.hpp"
#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/recorder.hpp"
#include "hapticgrasp/session/replay.hpp"
#include "contact/contact_fixtures.hpp"
#include "session/stepped_session.hpp"

namespace hg::session {
namespace {

namespace fs = std::filesystem;

std::string recordBench(const std::string& name, const std::string& method, int fingers, const std::string& part) {
  const fs::path dir = test::tempDir("replay");
  servo::ServoBenchOptions o;
  o.device = "scripted";
  o.method = method;
  o.fingers = fingers;
  o.part = part;
  o.seconds = 2.5;
  o.realtime = false;
  o.recordPath = (dir / name).string();
  const servo::ServoBenchResult r = servo::runServoBench(o);
  EXPECT_EQ(r.recording.droppedRecords, 0u);
  EXPECT_GE(r.grasps, 1u);
  return o.recordPath;
}

void expectIdentical(const ReplayCheck& c) {
  std::printf("%s\n", toJson(c).c_str());
  EXPECT_GT(c.ticks, 4000u);
  EXPECT_EQ(c.stateMismatches, 0u);
  EXPECT_EQ(c.eventMismatches, 0u);
  EXPECT_EQ(c.maxForceDiff_N, 0.0);
  EXPECT_EQ(c.maxPoseDiff_m, 0.0);
  EXPECT_EQ(c.firstMismatchTick, 0u);
  EXPECT_TRUE(c.complete);
}

// A recording whose description the servo loop refuses (its watchdog ramp out of range):
// a SessionError, as documented, not the loop's std::invalid_argument (fuzz_recording).
TEST(Replay, ADescriptionTheLoopRefusesIsASessionError) {
  EXPECT_THROW(replay(std::string(HG_TEST_DATA_DIR) + "/../fuzz/corpus/recording/crash_bad_watchdog_ramp.mcap"),
               SessionError);
}

TEST(Replay, TwoFingerSessionIsBitIdentical) {
  const std::string file = recordBench("two.mcap", "two-finger", 2, "cylinder");
  bool lifted = false;
  const ReplayCheck c = replay(file, [&](const servo::TickRecord& r, const servo::ServoSnapshot& s) {
    lifted |= r.state == grasp::GraspState::Manipulate && s.state == grasp::GraspState::Manipulate;
  });
  expectIdentical(c);
  EXPECT_TRUE(lifted);  // the comparison covered a carried part
}

TEST(Replay, MultiFingerSessionOnAnExactPartIsBitIdentical) {
  expectIdentical(replay(recordBench("multi.mcap", "multi-finger", 3, "block")));
}

// The hand of contact_fixtures.hpp that lowers a block onto a plate, read at the time given.
class LoweringHand final : public device::Device {
 public:
  const device::DeviceSpec& spec() const noexcept override { return spec_; }
  bool read(device::DeviceSample& s) noexcept override {
    s.hand = hg::test::handAt(keys_, now_s);
    return true;
  }
  void write(const device::DeviceCommand&) noexcept override {}
  double now_s = 0;

 private:
  std::vector<hg::test::HandKey> keys_ = hg::test::lowerOntoPlate(0.5);
  device::DeviceSpec spec_ = servo::ScriptedHandDevice::defaultSpec();
};

// Part-to-part contact replays bit for bit: the contact shells are rebuilt from the attached
// shapes and the recorded options, the coupling from the recorded parameters.
TEST(Replay, ASessionWithPartToPartContactIsBitIdentical) {
  const grasp::ScenePtr scene = hg::test::blockOverPlate(0.1);
  SessionDescription d = test::describeBench(*scene, servo::ScriptedHandDevice::defaultSpec(), 2000);
  d.contact = true;
  d.contactConfig.query.maxPoints = d.contactModel.maxPoints;
  const std::string file = (test::tempDir("replay-contact") / "contact.mcap").string();
  {
    auto hand = std::make_shared<LoweringHand>();
    servo::ServoConfig config;
    config.realtime = false;
    servo::ServoLoop loop(hand, rebuildEngine(d, scene), config);
    Recorder recorder(file, d, scene);
    loop.record(recorder.ring());
    recorder.start();
    for (int k = 0; k < 3800; ++k) {
      hand->now_s = k * 0.0005;
      loop.step(k * 0.0005, k ? 0.0005 : 0.0);
      if (k % 500 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    recorder.stop();
  }
  int touching = 0;
  double lowest = 1;
  const ReplayCheck c = replay(file, [&](const servo::TickRecord& r, const servo::ServoSnapshot& s) {
    touching += r.contact.part == 0 && r.contact.active > 0 && s.contact.active == r.contact.active;
    for (int k = 0; k < s.movingCount; ++k)
      if (s.moving[k].part == 0) lowest = std::min(lowest, s.moving[k].pose.position.z());
  });
  EXPECT_EQ(c.stateMismatches, 0u);
  EXPECT_EQ(c.maxForceDiff_N, 0.0);
  EXPECT_EQ(c.maxPoseDiff_m, 0.0);
  EXPECT_TRUE(c.complete);
  EXPECT_GT(touching, 100);  // the comparison covered a part standing on the plate
  EXPECT_GE(lowest, hg::test::kPlateTop - 5e-5);
}

TEST(Replay, RebuildsTheRecordedSceneFromTheAttachedShapes) {
  const std::string file = recordBench("scene.mcap", "two-finger", 2, "loft");
  McapReader reader(file);
  reader.scan({}, true);
  const SessionDescription d = readDescription(reader);
  const grasp::ScenePtr scene = rebuildScene(d);
  ASSERT_EQ(scene->size(), 1u);
  const geometry::SamplePart loft = geometry::findPart("loft");
  EXPECT_EQ(scene->part(0).model->faces().Extent(), geometry::PartModel::fromFile(loft.file, loft.unit)->faces().Extent());
  EXPECT_EQ(std::string(scene->part(0).penetration->name()), d.parts[0].backend);
  EXPECT_EQ(scene->part(0).mass.mass_kg, d.parts[0].mass.mass_kg);
}

// The swap is recorded once and replayed at its tick (the stand-in alone would differ).
TEST(Replay, PublishesTheRecordedModelSwapsAtTheirTicks) {
  const std::string file = (test::tempDir("replay") / "swapped.mcap").string();
  test::recordSwappedSession(file);
  const RecordingInfo info = readRecordingInfo(file);
  EXPECT_TRUE(info.description.parts[0].coarse);
  EXPECT_EQ(info.topics.at(std::string(kModelTopic)), 1u);
  bool lifted = false;
  const ReplayCheck c = replay(file, [&](const servo::TickRecord& r, const servo::ServoSnapshot&) {
    lifted |= r.state == grasp::GraspState::Manipulate;
  });
  expectIdentical(c);
  EXPECT_TRUE(lifted);
}

TEST(Replay, AFileThatIsNotARecordingGetsAClearError) {
  const fs::path file = test::tempDir("replay") / "not.mcap";
  { std::ofstream(file) << "hello"; }
  EXPECT_THROW(replay(file.string()), std::runtime_error);
}

}  // namespace
}  // namespace hg::session
