// A scene touchable at once: stand-ins first, each distinct shape built once, nearest the
// focus first, failures kept to their parts, the servo never allocating meanwhile.
#include "hapticgrasp/scene/scene_build.hpp"

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <mutex>
#include <chrono>
#include <cstdio>
#include <functional>
#include <thread>

#include "alloc_counter.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/servo/grasp_engine.hpp"
#include "hapticgrasp/servo/scripted_hand_device.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"

namespace hg::grasp {
namespace {

// `n` parts in a row along x, 0.1 m apart; parts i and j share a shape when i % shapes == j % shapes.
std::vector<PartSource> row(int n, int shapes, std::atomic<int>* loads = nullptr) {
  std::vector<PartSource> parts;
  for (int i = 0; i < n; ++i) {
    PartSource p;
    p.name = "part " + std::to_string(i);
    p.key = "shape " + std::to_string(i % shapes);
    const double size = 10 + i % shapes;  // mm: each shape its own size
    p.bounds = {Vec3::Zero(), Vec3::Constant(size / 1000)};
    p.pose.position = Vec3(0.1 * i, 0, 0);
    p.mass = geometry::MassSpec::density(1000 + i);
    p.load = [size, loads] {
      if (loads) ++*loads;
      return geometry::PartModel::fromShape(BRepPrimAPI_MakeBox(size, size, size + 1).Shape(),
                                            geometry::LengthUnit::Millimetre, "box");
    };
    parts.push_back(std::move(p));
  }
  return parts;
}

TEST(SceneBuild, StandInsAtOnceThenEveryDistinctShapeBuiltOnce) {
  std::atomic<int> loads{0};
  SceneBuild build(row(30, 3, &loads));
  const ScenePtr scene = build.scene();
  ASSERT_EQ(scene->size(), 30u);
  ASSERT_TRUE(build.wait(120));
  EXPECT_EQ(loads.load(), 3);
  const SceneBuild::Progress p = build.progress();
  EXPECT_EQ(p.models, 3u);
  EXPECT_EQ(p.built, 3u);
  EXPECT_EQ(p.exactParts, 30u);
  EXPECT_TRUE(p.finished);
  for (std::size_t i = 0; i < 30; ++i) {
    const ScenePart& part = scene->part(i);
    EXPECT_FALSE(part.coarse) << i;
    EXPECT_EQ(part.penetration.get(), scene->part(i % 3).penetration.get()) << "shared model, part " << i;
    EXPECT_EQ(part.initialPose.position.x(), 0.1 * static_cast<double>(i));
    const double size = 0.010 + 0.001 * static_cast<double>(i % 3);
    EXPECT_NEAR(part.mass.mass_kg, (1000.0 + static_cast<double>(i)) * size * size * (size + 0.001), 1e-12)
        << "each part's own density";
  }
}

// With contact, every shape gets its contact shell, shared like its model, published after
// the model (the exact surface is felt first): two publications a part, exact parts
// counted once.
TEST(SceneBuild, ContactShellsFollowTheModelsAndAreShared) {
  SceneBuild::Options options;
  options.contact = true;
  options.contactOptions.maxPoints = 64;
  SceneBuild build(row(6, 2), options);
  const ScenePtr scene = build.scene();
  EXPECT_EQ(scene->part(0).contact, nullptr);  // a stand-in has none
  ASSERT_TRUE(build.wait(120));
  const SceneBuild::Progress p = build.progress();
  EXPECT_EQ(p.exactParts, 6u);
  EXPECT_EQ(scene->publications(), 12u);
  for (std::size_t i = 0; i < 6; ++i) {
    ASSERT_NE(scene->part(i).contact, nullptr) << i;
    EXPECT_EQ(scene->part(i).contact.get(), scene->part(i % 2).contact.get()) << i;
    EXPECT_LE(scene->part(i).contact->shell().size(), 64u);
    EXPECT_EQ(&scene->part(i).contact->part(), scene->part(i).model.get());
  }
  for (const SceneBuild::Model& m : build.models()) EXPECT_TRUE(m.contactError.empty()) << m.contactError;
}

// Each load waits for the test's leave, so that the focus moves between two picks whatever
// the machine's load: the worker's picks follow the focus as it is at each pick.
TEST(SceneBuild, BuildsTheShapeNearestTheFocusFirst) {
  std::vector<std::size_t> order;
  std::mutex mutex;
  std::condition_variable changed;
  std::size_t released = 0;
  auto parts = row(12, 12);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    auto load = parts[i].load;
    parts[i].load = [load, i, &order, &mutex, &changed, &released] {
      std::unique_lock lock(mutex);
      order.push_back(i);
      changed.notify_all();
      changed.wait(lock, [&] { return released >= order.size(); });
      return load();
    };
  }
  const auto waitPick = [&](std::size_t picks) {  // until the worker has made pick `picks`
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(60), [&] { return order.size() >= picks; });
  };
  const auto release = [&](std::size_t loads) {  // let the first `loads` picks build
    std::lock_guard lock(mutex);
    released = loads;
    changed.notify_all();
  };
  SceneBuild build(std::move(parts));
  struct ReleaseAll {  // a failed assertion must not leave the worker waiting (the build joins it)
    std::function<void()> go;
    ~ReleaseAll() { go(); }
  } releaseAll{[&] { release(100); }};
  build.setFocus(Vec3(0.7, 0, 0));  // part 7 (a first pick may have been made before: part 0)
  ASSERT_TRUE(waitPick(1));
  release(1);
  ASSERT_TRUE(waitPick(2));         // picked with the focus at part 7
  build.setFocus(Vec3(0.2, 0, 0));  // the hand moved: part 2 and its neighbours next
  release(2);
  ASSERT_TRUE(waitPick(3));
  release(100);
  ASSERT_TRUE(build.wait(120));
  ASSERT_EQ(order.size(), 12u);
  const auto pos = [&](std::size_t part) { return std::find(order.begin(), order.end(), part) - order.begin(); };
  EXPECT_LE(pos(7), 1);
  EXPECT_EQ(order[1], order[0] == 7 ? 6u : 7u);  // after 7, its nearer neighbour
  EXPECT_EQ(order[2], 2u);
  EXPECT_LT(pos(2), pos(11));
  EXPECT_LT(pos(3), pos(10));
  EXPECT_LT(pos(1), pos(9));
}

TEST(SceneBuild, AShapeThatFailsKeepsItsStandInAndSaysWhy) {
  auto parts = row(4, 4);
  parts[2].load = []() -> geometry::PartModelPtr { throw geometry::GeometryError("not a solid: an open shell"); };
  SceneBuild build(std::move(parts));
  ASSERT_TRUE(build.wait(120));
  EXPECT_EQ(build.progress().failed, 1u);
  EXPECT_EQ(build.progress().exactParts, 3u);
  EXPECT_TRUE(build.scene()->part(2).coarse);
  const auto models = build.models();
  EXPECT_EQ(models[build.modelOf(2)].status, SceneBuild::Model::Status::Failed);
  EXPECT_EQ(models[build.modelOf(2)].error, "not a solid: an open shell");
}

TEST(SceneBuild, RefusesPartsWithoutABox) {
  auto parts = row(2, 2);
  parts[1].bounds = geometry::Aabb{};
  EXPECT_THROW(SceneBuild{std::move(parts)}, std::invalid_argument);
}

// The workbench hands shapes over as it exports them: the build asks for the nearest first
// and waits for them; the servo's scene meanwhile answers with the stand-ins.
TEST(SceneBuild, ShapesThatComeLaterAreAskedForNearestFirst) {
  auto parts = row(6, 3);
  std::vector<std::function<geometry::PartModelPtr()>> loads;
  for (auto& p : parts) {
    loads.push_back(p.load);
    p.load = nullptr;
  }
  SceneBuild build(std::move(parts));
  build.setFocus(Vec3(0.5, 0, 0));  // part 5 (shape 2), then 4 (shape 1), then 3 (shape 0)
  EXPECT_EQ(build.awaitingShapes(10), (std::vector<std::size_t>{2, 1, 0}));
  EXPECT_EQ(build.awaitingShapes(1), (std::vector<std::size_t>{2}));
  EXPECT_FALSE(build.wait(0.05));  // nothing to build yet: it waits
  build.provide(2, loads[2]);
  EXPECT_THROW(build.provide(2, loads[2]), std::logic_error);
  while (build.progress().built < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_FALSE(build.scene()->part(5).coarse);
  EXPECT_FALSE(build.scene()->part(2).coarse);
  EXPECT_TRUE(build.scene()->part(4).coarse);
  EXPECT_EQ(build.awaitingShapes(10), (std::vector<std::size_t>{1, 0}));
  build.provide(0, loads[0]);
  build.provide(1, loads[1]);
  ASSERT_TRUE(build.wait(60));
  EXPECT_EQ(build.progress().exactParts, 6u);
}

// A restart with the parts elsewhere: a new scene with the models so far, and the later
// ones published to it too.
TEST(SceneBuild, ARebasedSceneGetsTheModelsStillToCome) {
  auto parts = row(4, 4);
  auto late = parts[3].load;
  parts[3].load = nullptr;
  SceneBuild build(std::move(parts));
  while (build.progress().built < 3) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::vector<PartPose> poses(4);
  poses[3].position = Vec3(0, 1, 0);
  const ScenePtr moved = build.rebase(poses);
  EXPECT_EQ(build.scene(), moved);
  EXPECT_FALSE(moved->part(0).coarse);
  EXPECT_TRUE(moved->part(3).coarse);
  EXPECT_EQ(moved->part(3).initialPose.position.y(), 1);
  EXPECT_THROW(build.rebase(std::vector<PartPose>(3)), std::invalid_argument);
  build.provide(3, late);
  ASSERT_TRUE(build.wait(60));
  EXPECT_FALSE(moved->part(3).coarse);
  EXPECT_EQ(moved->part(3).initialPose.position.y(), 1);
}

TEST(SceneBuild, CancelStopsAfterTheModelInProgress) {
  auto parts = row(20, 20);
  for (auto& p : parts) {
    auto load = p.load;
    p.load = [load] {
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
      return load();
    };
  }
  SceneBuild build(std::move(parts));
  std::this_thread::sleep_for(std::chrono::milliseconds(40));
  build.cancel();
  ASSERT_TRUE(build.wait(10));
  EXPECT_TRUE(build.progress().finished);
  EXPECT_LT(build.progress().built, 5u);
}

// The servo's CPU is left out only when two others remain.
TEST(SceneBuild, BackgroundWorkKeepsOffTheServosCpuWhenTwoOthersRemain) {
  const auto cpus = [](std::initializer_list<int> list) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (int c : list) CPU_SET(c, &set);
    return set;
  };
  const auto same = [](const cpu_set_t& a, const cpu_set_t& b) { return CPU_EQUAL(&a, &b) != 0; };
  EXPECT_TRUE(same(backgroundCpus(cpus({0, 1, 2, 3}), 3), cpus({0, 1, 2})));
  EXPECT_TRUE(same(backgroundCpus(cpus({0, 1, 2}), 1), cpus({0, 2})));
  EXPECT_TRUE(same(backgroundCpus(cpus({0, 1}), 1), cpus({0, 1})));  // one other: both
  EXPECT_TRUE(same(backgroundCpus(cpus({4}), 4), cpus({4})));
  EXPECT_TRUE(same(backgroundCpus(cpus({0, 1, 2}), -1), cpus({0, 1, 2})));  // no servo CPU
  EXPECT_TRUE(same(backgroundCpus(cpus({0, 1, 2}), 7), cpus({0, 1, 2})));   // not among them
}

// The workers run in the background (SCHED_BATCH, nice 19) where backgroundCpus puts them
// on this machine.
TEST(SceneBuild, WorkersRunInTheBackgroundWhereBackgroundCpusSays) {
  const int servo = servo::servoCpu();
  cpu_set_t allowed;
  ASSERT_EQ(pthread_getaffinity_np(pthread_self(), sizeof allowed, &allowed), 0);
  const cpu_set_t expected = servo < 0 ? allowed : backgroundCpus(allowed, servo);
  auto parts = row(3, 3);
  std::atomic<int> asExpected{0}, batch{0}, nice19{0}, checked{0};
  for (auto& p : parts) {
    auto load = p.load;
    p.load = [load, expected, &asExpected, &batch, &nice19, &checked] {
      cpu_set_t set;
      pthread_getaffinity_np(pthread_self(), sizeof set, &set);
      asExpected += CPU_EQUAL(&set, &expected) ? 1 : 0;
      batch += sched_getscheduler(0) == SCHED_BATCH ? 1 : 0;
      errno = 0;
      nice19 += getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())) == 19 && errno == 0 ? 1 : 0;
      ++checked;
      return load();
    };
  }
  SceneBuild::Options options;
  options.avoidCpu = servo;
  SceneBuild build(std::move(parts), options);
  ASSERT_TRUE(build.wait(60));
  EXPECT_EQ(checked.load(), 3);
  EXPECT_EQ(asExpected.load(), 3);
  EXPECT_EQ(batch.load(), 3);
  EXPECT_EQ(nice19.load(), 3);
  std::printf("%d CPUs allowed: the workers run on %d of them\n", CPU_COUNT(&allowed), CPU_COUNT(&expected));
}

// The real servo thread on a scene whose models are swapped in while it runs: no
// allocation, the hand feels the part throughout.
TEST(SceneBuild, TheServoNeverAllocatesWhileModelsComeIn) {
  auto parts = row(200, 50);
  for (auto& p : parts) {
    auto load = p.load;
    p.load = [load] {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      return load();
    };
  }
  SceneBuild build(std::move(parts));
  std::vector<HandKey> keys(2);
  keys[0].t = 0;
  keys[1].t = 100;
  for (HandKey& k : keys) {  // the index 1 mm inside the top of part 0 (a 10 x 10 x 11 mm box)
    k.index = Vec3(0.005, 0.005, 0.010);
    k.thumb = Vec3(0.005, 0.005, 0.3);
    k.wrist = Vec3(0.005, 0.005, 0.4);
  }
  auto device = std::make_shared<servo::ScriptedHandDevice>(HandScript(std::move(keys)));
  servo::ServoConfig config;
  config.rate_hz = 2000;
  config.realtime = false;
  config.allocationCounter = &hg::servo::threadAllocations;
  servo::ServoLoop loop(device, std::make_unique<servo::TwoFingerEngine>(build.scene()), config);
  loop.start();
  ASSERT_TRUE(build.wait(120));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  loop.stop();
  servo::ServoSnapshot s;
  ASSERT_TRUE(loop.read(s));
  EXPECT_EQ(build.progress().exactParts, 200u);
  EXPECT_GT(s.tick, 100u);
  EXPECT_EQ(s.allocations, 0);
  EXPECT_EQ(s.state, GraspState::IndexContact);  // 1 mm in, whichever model answered
}

}  // namespace
}  // namespace hg::grasp
