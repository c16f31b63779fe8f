// The session's snapshot carries what the task panel and the overlay show: the forces the
// operator feels, the grasping force, the hand in mm, and the servo's rate.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <unistd.h>

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepTools.hxx>

#include "haptic_session.hpp"
#include "hapticgrasp/servo/realtime_access.hpp"
#include "hapticgrasp/session/recording.hpp"

namespace hg::freecad {
namespace {

std::string cylinderBrep() {
  std::ifstream in(std::string(HG_RESOURCES_DIR) + "/parts/cylinder.brep");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(HapticSession, SnapshotCarriesForcesHandAndRate) {
  Session session;
  // The cylinder (axis z, diameter 100 mm) stands where the document put it.
  session.addPart("Cylinder", cylinderBrep(), Placement{{0, 0, 200}, {0, 0, 0, 1}}, geometry::MassSpec::mass(2));
  session.useHandInput(0.5);
  session.start(1000, false);
  // Squeeze it across its diameter: index 5 mm inside at +x, thumb 5 mm inside at -x.
  const std::array<double, 3> index{45, 0, 200}, thumb{-45, 0, 200}, wrist{0, -100, 200};
  SessionSnapshot snap;
  for (int i = 0; i < 300; ++i) {
    session.setHand(index, thumb, wrist);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  snap = session.snapshot();
  session.stop();
  EXPECT_EQ(snap.state, "GRASP");
  EXPECT_GT(snap.graspForce_N, 1.0);
  // The index is pushed towards +x (apart from the thumb), the thumb towards -x.
  EXPECT_GT(snap.forces_N[0][0], 1.0);
  EXPECT_LT(snap.forces_N[1][0], -1.0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(snap.index_mm[k], index[k], 1e-9);
    EXPECT_NEAR(snap.thumb_mm[k], thumb[k], 1e-9);
    EXPECT_NEAR(snap.wrist_mm[k], wrist[k], 1e-9);
  }
  EXPECT_GT(snap.rate_hz, 100.0);  // ran; the figure itself is not asserted
  EXPECT_TRUE(std::isfinite(snap.jitter_us));
}

std::string blockBrep() {
  std::ifstream in(std::string(HG_RESOURCES_DIR) + "/parts/block.brep");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ModelBuild, BuildsOnItsWorkerWithProgressAndNamesABadPart) {
  std::vector<PartRequest> requests;
  for (int i = 0; i < 3; ++i)
    requests.push_back({"Block" + std::to_string(i), blockBrep(), Placement{{0, 400.0 * i, 0}, {0, 0, 0, 1}},
                        geometry::MassSpec::density(1000)});
  requests.insert(requests.begin() + 1, PartRequest{"Broken", "not a brep", Placement{}, geometry::MassSpec::density(1000)});
  ModelBuild build(std::move(requests));
  // The constructor returned at once: the caller polls while the worker builds.
  std::vector<std::size_t> seen{build.progress().done};
  int polls = 0;
  while (!build.progress().finished) {
    ++polls;
    const std::size_t done = build.progress().done;
    if (done != seen.back()) seen.push_back(done);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_EQ(seen.front(), 0u);
  EXPECT_GT(polls, 3);
  EXPECT_GE(seen.size(), 2u);
  const auto progress = build.progress();
  EXPECT_EQ(progress.done, 4u);
  EXPECT_FALSE(progress.cancelled);
  const auto outcomes = build.outcomes();
  ASSERT_EQ(outcomes.size(), 4u);
  EXPECT_FALSE(outcomes[1].built);
  EXPECT_EQ(outcomes[1].name, "Broken");
  EXPECT_FALSE(outcomes[1].error.empty());
  Session session;
  const auto added = session.addBuilt(build);
  ASSERT_EQ(added.size(), 3u);
  EXPECT_EQ(added[1].first, 2u);  // request 2 became part 1
  EXPECT_EQ(session.partCount(), 3u);
  EXPECT_EQ(session.partInfo(1).name, "Block1");
}

TEST(ModelBuild, CancelStopsAfterThePartInProgressAndAddsNothing) {
  std::vector<PartRequest> requests;
  for (int i = 0; i < 5; ++i)
    requests.push_back({"Block" + std::to_string(i), blockBrep(), Placement{}, geometry::MassSpec::density(1000)});
  ModelBuild build(std::move(requests));
  build.cancel();
  EXPECT_TRUE(build.wait(60));
  const auto progress = build.progress();
  EXPECT_TRUE(progress.finished);
  EXPECT_TRUE(progress.cancelled);
  EXPECT_LE(progress.done, 1u);
  Session session;
  EXPECT_THROW(session.addBuilt(build), std::logic_error);
  EXPECT_EQ(session.partCount(), 0u);
}

TEST(ModelBuild, AnOpenBuildTakesPartsUntilClosed) {
  ModelBuild build({}, true);
  build.add({"Block0", blockBrep(), Placement{}, geometry::MassSpec::density(1000)});
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(build.progress().finished);  // open: waits for more
  build.add({"Block1", blockBrep(), Placement{{0, 400, 0}, {0, 0, 0, 1}}, geometry::MassSpec::density(1000)});
  build.close();
  EXPECT_THROW(build.add({"Late", blockBrep(), Placement{}, geometry::MassSpec::density(1000)}), std::logic_error);
  ASSERT_TRUE(build.wait(60));
  EXPECT_EQ(build.progress().done, 2u);
  EXPECT_EQ(build.progress().total, 2u);
  EXPECT_FALSE(build.progress().cancelled);
  Session session;
  EXPECT_EQ(session.addBuilt(build).size(), 2u);
  // Cancelling an open build that waits for parts ends it at once, cancelled.
  ModelBuild open({}, true);
  open.cancel();
  ASSERT_TRUE(open.wait(5));
  EXPECT_TRUE(open.progress().cancelled);
}

TEST(HapticSession, ReplacePartAndRestartMakeTheNewShapeFelt) {
  Session session;
  session.addPart("Block", blockBrep(), Placement{{-500, 0, 0}, {0, 0, 0, 1}}, geometry::MassSpec::density(1000));
  session.addPart("Part", cylinderBrep(), Placement{{0, 0, 200}, {0, 0, 0, 1}}, geometry::MassSpec::mass(2));
  // The index 80 mm from the cylinder's axis (radius 50): free. The thumb far away.
  const std::array<double, 3> index{80, 0, 200}, thumb{-300, 0, 200}, wrist{0, -100, 300};
  session.useHandInput(0.5);
  session.start(1000, false);
  const auto feed = [&](int ms) {
    for (int k = 0; k < ms; ++k) {
      session.setHand(index, thumb, wrist);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return session.snapshot();
  };
  const SessionSnapshot before = feed(200);
  EXPECT_EQ(before.state, "FREE");
  EXPECT_EQ(before.forces_N[0][0], 0.0);
  // The part is edited into a 200 mm cube centred where the cylinder stood.
  std::ostringstream cube;
  BRepTools::Write(BRepPrimAPI_MakeBox(gp_Pnt(-100, -100, -100), 200, 200, 200).Shape(), cube);
  ModelBuild build({PartRequest{"Part", cube.str(), Placement{{0, 0, 200}, {0, 0, 0, 1}}, geometry::MassSpec::mass(2)}});
  ASSERT_TRUE(build.wait(60));
  session.replacePart(1, build);
  EXPECT_NEAR(session.partInfo(1).boundsMax_mm[0], 100, 1e-6);
  EXPECT_EQ(session.partInfo(0).faces, 58);  // untouched
  session.restart({Placement{{-500, 0, 0}, {0, 0, 0, 1}}, Placement{{0, 0, 200}, {0, 0, 0, 1}}});
  EXPECT_TRUE(session.running());
  const SessionSnapshot after = feed(300);
  session.stop();
  EXPECT_EQ(after.state, "INDEX CONTACT");
  EXPECT_GT(after.forces_N[0][0], 0.1);  // pushed out through the cube's +x face
  EXPECT_GT(after.time_s, before.time_s);  // time and ticks carry on across the restart
  EXPECT_GT(after.tick, before.tick);
}

// The multi-finger method's k, k_d, μ, γ are the session's to set, checked, and reach the
// engine: the recording's description (what replay rebuilds the engine from) holds them.
TEST(HapticSession, TheMultiFingerParametersReachTheEngine) {
  Session session;
  EXPECT_EQ(session.parameter("k"), 800);
  EXPECT_EQ(session.parameter("mu"), 1);
  EXPECT_THROW(session.setParameters({{"k", -1}}), std::invalid_argument);
  EXPECT_THROW(session.setParameters({{"gamma3", 0}}), std::invalid_argument);
  EXPECT_EQ(session.parameter("k"), 800);  // a refused set changes nothing
  session.setParameters({{"k", 400}, {"k_d", 600}, {"mu", 0.5}, {"gamma2", 2e-3}});
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("hg_session_mf_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::string path = (dir / "mf.mcap").string();
  session.addPart("Cylinder", cylinderBrep(), Placement{{0, 0, 200}, {0, 0, 0, 1}}, geometry::MassSpec::mass(2));
  session.useHandInput(0.5);
  session.setMethod("multi-finger");
  session.recordTo(path, "");
  session.start(1000, false);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  session.stop();
  const auto recorded = session::readRecordingInfo(path).description.multiFinger.grasp;
  EXPECT_EQ(recorded.stiffness, 400);
  EXPECT_EQ(recorded.dynamicsStiffness, 600);
  EXPECT_EQ(recorded.friction, 0.5);
  EXPECT_EQ(recorded.distribution.gamma2, 2e-3);
  std::filesystem::remove_all(dir);
}

// The workbench's default: 2 kHz, asking for SCHED_FIFO and locked memory; the session says
// what it got and, when refused, why and how to get it (as the probe finds it).
TEST(HapticSession, RunsAt2kHzAskingForRealTimeAndSaysWhatItGot) {
  Session session;
  EXPECT_EQ(session.servoTiming().scheduler, "not started");
  session.addPart("Cylinder", cylinderBrep(), Placement{{0, 0, 200}, {0, 0, 0, 1}}, geometry::MassSpec::mass(2));
  session.useHandInput(0.5);
  session.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const ServoTiming t = session.servoTiming();
  session.stop();
  EXPECT_EQ(t.target_hz, 2000);
  EXPECT_GT(t.ticks, 64u);
  EXPECT_GT(t.achieved_hz, 0);
  EXPECT_LE(t.periodErrP50_us, t.periodErrP99_us);
  EXPECT_LE(t.periodErrP99_us, t.periodErrMax_us);
  const servo::RealtimeAccess access = servo::probeRealtime(servo::ServoConfig{}.fifoPriority);
  EXPECT_EQ(t.realtime, access.granted) << t.scheduler;
  EXPECT_EQ(t.scheduler == "SCHED_FIFO", access.granted);
  EXPECT_EQ(t.advice.empty(), access.granted);
  if (!access.granted) EXPECT_NE(t.advice.find("usermod -aG hapticgrasp"), std::string::npos) << t.advice;
  std::printf("servo: %s, %s, %.0f of %.0f Hz, period error p99 %.1f us\n", t.scheduler.c_str(), t.memoryLock.c_str(),
              t.achieved_hz, t.target_hz, t.periodErrP99_us);
}

}  // namespace
}  // namespace hg::freecad

namespace hg::freecad {
namespace {

// Scene mode: the servo runs on the parts' boxes at once; two cylinders share one model
// (one key) and get it when their shape is provided; the block keeps its box meanwhile.
TEST(HapticSessionScene, StartsOnTheBoxesAndTakesEachShapeOnce) {
  Session session;
  const auto request = [](const std::string& name, const std::string& key, double x, std::array<double, 3> lo,
                          std::array<double, 3> hi) {
    return SceneRequest{name, key, lo, hi, Placement{{x, 0, 0}, {0, 0, 0, 1}}, geometry::MassSpec::density(1000)};
  };
  // The sample cylinder: diameter 100 mm, 400 mm long along z, centred.
  const std::array<double, 3> cMin{-50, -50, -200}, cMax{50, 50, 200};
  session.useHandInput(0.5);
  session.startScene({request("A", "cyl", 0, cMin, cMax), request("B", "cyl", 300, cMin, cMax),
                      request("Block", "block", 600, {-60, -60, -60}, {60, 60, 60})},
                     1000, false);
  EXPECT_TRUE(session.running());
  EXPECT_EQ(session.partCount(), 3u);
  EXPECT_EQ(session.modelOfPart(0), session.modelOfPart(1));
  EXPECT_NE(session.modelOfPart(0), session.modelOfPart(2));
  SceneStatus st = session.sceneStatus();
  EXPECT_EQ(st.models, 2u);
  EXPECT_EQ(st.exactParts, 0u);
  // The hand near B: its shape is wanted first. Touch a corner of its box, outside the cylinder.
  const std::array<double, 3> corner{300 + 45, 45, 0}, far{-500, 0, 0}, wrist{-500, 0, 100};
  for (int i = 0; i < 50; ++i) {
    session.setHand(corner, far, wrist);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  SessionSnapshot snap = session.snapshot();
  EXPECT_EQ(snap.state, "INDEX CONTACT");  // the box answers
  EXPECT_EQ(snap.backends[1].first, "box");
  EXPECT_EQ(snap.exactParts, 0u);
  const auto wanted = session.wantedShapes(8);
  ASSERT_EQ(wanted.size(), 2u);
  EXPECT_EQ(wanted[0], session.modelOfPart(1));
  session.provideShape(wanted[0], cylinderBrep());
  for (int i = 0; i < 2000 && session.sceneStatus().built < 1; ++i) {
    session.setHand(corner, far, wrist);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  for (int i = 0; i < 20; ++i) {
    session.setHand(corner, far, wrist);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  snap = session.snapshot();
  EXPECT_EQ(snap.state, "FREE");  // the cylinder's own model: the corner is outside it
  EXPECT_EQ(snap.exactParts, 2u);
  EXPECT_EQ(snap.backends[0].first, "analytic");
  EXPECT_EQ(snap.backends[1].first, "analytic");
  EXPECT_EQ(snap.backends[2].first, "box");
  EXPECT_EQ(session.modelInfo(session.modelOfPart(0)).faces, 3);
  session.provideShape(session.modelOfPart(2), blockBrep());
  for (int i = 0; i < 5000 && !session.sceneStatus().finished; ++i) {
    session.setHand(corner, far, wrist);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  st = session.sceneStatus();
  EXPECT_TRUE(st.finished);
  EXPECT_EQ(st.exactParts, 3u);
  // A restart with B moved 100 mm along y: the models stay, the parts stand anew.
  session.restart({Placement{{0, 0, 0}, {0, 0, 0, 1}}, Placement{{300, 100, 0}, {0, 0, 0, 1}},
                   Placement{{600, 0, 0}, {0, 0, 0, 1}}});
  for (int i = 0; i < 20; ++i) {
    session.setHand(corner, far, wrist);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  snap = session.snapshot();
  session.stop();
  EXPECT_NEAR(snap.placements[1].base_mm[1], 100, 1e-9);
  EXPECT_EQ(snap.backends[1].first, "analytic");
  EXPECT_EQ(snap.exactParts, 3u);
}

TEST(HapticSessionScene, RefusesNoPartsOrNoDevice) {
  Session session;
  EXPECT_THROW(session.startScene({}, 1000, false), std::invalid_argument);
  EXPECT_THROW(session.startScene({SceneRequest{"A", "", {0, 0, 0}, {1, 1, 1}, {}, geometry::MassSpec::density(1000)}},
                                  1000, false),
               std::invalid_argument);
  EXPECT_FALSE(session.running());
  EXPECT_THROW(session.wantedShapes(1), std::logic_error);
}

// Recording: the scripted hand squeezes the cylinder; a note taken meanwhile names it. The
// file reads complete, with both parts named and nothing dropped; a restart() goes on in
// "<name>-2.mcap" beside it.
TEST(HapticSession, RecordsTheSessionWithItsPartsAndANote) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("hg_session_rec_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::string path = (dir / "review.mcap").string();
  Session session;
  session.addPart("Cylinder", cylinderBrep(), Placement{{0, 0, 200}, {0, 0, 0, 1}}, geometry::MassSpec::mass(2));
  session.addPart("Block", blockBrep(), Placement{{-500, 0, 0}, {0, 0, 0, 1}}, geometry::MassSpec::density(1000));
  // Open around the cylinder (diameter 100 mm), then squeezing it 5 mm deep on each side.
  const std::array<double, 3> wrist{0, -100, 200};
  std::vector<HandKeyMm> keys{{0.0, {80, 0, 200}, {-80, 0, 200}, wrist},
                              {0.5, {45, 0, 200}, {-45, 0, 200}, wrist},
                              {10.0, {45, 0, 200}, {-45, 0, 200}, wrist}};
  session.setHandScript(keys, Placement{}, {0, 0, 0});
  EXPECT_THROW(session.annotate("too early"), std::logic_error);
  session.recordTo(path, "Test.FCStd");
  session.start(1000, false);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const SessionSnapshot snap = session.snapshot();
  EXPECT_EQ(snap.state, "GRASP");
  // The note is stamped when N is pressed, not when the reviewer has typed it.
  const Session::NoteMark mark = session.markNote();
  EXPECT_EQ(mark.part, "Cylinder");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  session.annotate("the grip slips here", mark);
  EXPECT_TRUE(session.recordingStatus().recording);
  session.restart(snap.placements);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  session.stop();
  EXPECT_THROW(session.recordTo(path, ""), std::logic_error);

  const RecordingStatus status = session.recordingStatus();
  EXPECT_FALSE(status.recording);
  EXPECT_EQ(status.error, "");
  ASSERT_EQ(status.files.size(), 2u);
  EXPECT_EQ(status.files[0], path);
  EXPECT_EQ(status.files[1], (dir / "review-2.mcap").string());
  EXPECT_EQ(status.path, status.files[1]);
  EXPECT_EQ(status.dropped, 0u);
  EXPECT_EQ(status.annotations, 1u);
  EXPECT_GT(status.ticks, 1000u);
  EXPECT_GT(status.duration_s, 1.5);

  const session::RecordingInfo info = session::readRecordingInfo(path);
  EXPECT_TRUE(info.complete);
  EXPECT_EQ(info.description.document, "Test.FCStd");
  EXPECT_EQ(info.description.partNames(), (std::vector<std::string>{"Cylinder", "Block"}));
  EXPECT_EQ(info.description.method, "two-finger");
  EXPECT_EQ(info.description.rate_hz, 1000);
  ASSERT_EQ(info.annotations.size(), 1u);
  EXPECT_EQ(info.annotations[0].text, "the grip slips here");
  EXPECT_EQ(info.annotations[0].part, "Cylinder");
  EXPECT_NEAR(info.annotations[0].time_s, 1.5, 0.5);
  // At the mark (read times count from the first tick, a few ms in under load), not 200 ms later.
  EXPECT_NEAR(info.annotations[0].time_s, mark.time_s, 0.05);
  EXPECT_TRUE(info.droppedKnown);
  EXPECT_EQ(info.droppedRecords, 0u);
  EXPECT_GT(info.topics.at(std::string(session::kTickTopic)), 1000u);
  const session::RecordingInfo second = session::readRecordingInfo(status.files[1]);
  EXPECT_TRUE(second.complete);
  EXPECT_TRUE(second.annotations.empty());
  EXPECT_GT(second.topics.at(std::string(session::kTickTopic)), 100u);
  std::filesystem::remove_all(dir);
}

TEST(HapticSession, AFileThatCannotBeCreatedLeavesHapticsRunningAndSaysWhy) {
  Session session;
  session.addPart("Cylinder", cylinderBrep(), Placement{{0, 0, 200}, {0, 0, 0, 1}}, geometry::MassSpec::mass(2));
  session.useHandInput(0.5);
  session.recordTo("/proc/no/such/dir/x.mcap", "");
  session.start(1000, false);
  EXPECT_TRUE(session.running());
  const RecordingStatus status = session.recordingStatus();
  EXPECT_FALSE(status.recording);
  EXPECT_NE(status.error.find("cannot record to /proc/no/such/dir/x.mcap"), std::string::npos) << status.error;
  EXPECT_THROW(session.annotate("no file"), std::logic_error);
  session.stop();
}

}  // namespace
}  // namespace hg::freecad
