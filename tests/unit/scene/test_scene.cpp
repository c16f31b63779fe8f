// A scene's models can be swapped while readers use it; bad models are refused; the log of
// swaps says which part changed, or that it wrapped.
#include "hapticgrasp/scene/scene.hpp"

#include <BRepPrimAPI_MakeCylinder.hxx>
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "hapticgrasp/scene/model_swaps.hpp"
#include "hapticgrasp/grasp/two_finger_grasp.hpp"

namespace hg::grasp {
namespace {

geometry::PartModelPtr cylinder() {  // 40 mm across, 40 mm high, centred
  static const auto model = geometry::PartModel::fromShape(
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -20), gp_Dir(0, 0, 1)), 20, 40).Shape(),
      geometry::LengthUnit::Millimetre, "cylinder");
  return model;
}

const geometry::Aabb kBox{Vec3::Constant(-0.02), Vec3::Constant(0.02)};

std::shared_ptr<const Scene> coarseScene(int n) {
  std::vector<ScenePart> parts;
  for (int i = 0; i < n; ++i) {
    PartPose pose;
    pose.position = Vec3(0.1 * i, 0, 0);
    parts.push_back(makeCoarseScenePart(kBox, geometry::MassSpec::density(1000), pose));
  }
  return std::make_shared<const Scene>(std::move(parts));
}

TEST(Scene, PublishSwapsAPartsModelsAndKeepsItsPose) {
  const auto scene = coarseScene(3);
  EXPECT_TRUE(scene->part(1).coarse);
  EXPECT_EQ(scene->part(1).penetration->name(), "box");
  const ScenePart& before = scene->part(1);
  const ScenePart& after = scene->publish(1, makeScenePart(cylinder(), geometry::MassSpec::density(1000), {}));
  EXPECT_EQ(&scene->part(1), &after);
  EXPECT_FALSE(after.coarse);
  EXPECT_EQ(after.penetration->name(), "analytic");
  EXPECT_EQ(after.initialPose.position.x(), 0.1);          // the part's pose, not the model's
  EXPECT_EQ(before.penetration->name(), "box");            // the old models stay alive
  EXPECT_EQ(scene->publications(), 1u);
  EXPECT_EQ(scene->publishedPart(0), 1);
  EXPECT_EQ(scene->publishedPart(1), -1);                  // not yet made
  EXPECT_TRUE(scene->part(0).coarse);
}

TEST(Scene, RefusesBadModelsAndChangesNothing) {
  const auto scene = coarseScene(2);
  ScenePart noMass = makeScenePart(cylinder(), geometry::MassSpec::density(1000), {});
  noMass.mass.mass_kg = 0;
  EXPECT_THROW(scene->publish(0, noMass), std::invalid_argument);
  ScenePart noModel;
  EXPECT_THROW(scene->publish(0, noModel), std::invalid_argument);
  EXPECT_THROW(scene->publish(2, makeScenePart(cylinder(), geometry::MassSpec::density(1000), {})), std::out_of_range);
  EXPECT_TRUE(scene->part(0).coarse);
  EXPECT_EQ(scene->publications(), 0u);
}

TEST(Scene, TheSwapLogWrapsAndFollowersSweepEveryPart) {
  const auto scene = coarseScene(5);
  ModelSwaps swaps(*scene);
  const ScenePart exact = makeScenePart(cylinder(), geometry::MassSpec::density(1000), {});
  for (std::uint64_t k = 0; k < Scene::kPublicationLog + 3; ++k) scene->publish(k % 5, exact);
  EXPECT_EQ(scene->publishedPart(0), -1);  // wrapped
  EXPECT_EQ(scene->publishedPart(Scene::kPublicationLog + 2), static_cast<int>((Scene::kPublicationLog + 2) % 5));
  std::vector<int> refitted;
  swaps.follow(*scene, [&](int part) { refitted.push_back(part); });
  EXPECT_TRUE(refitted.empty());  // it noticed the wrap: the sweep comes next tick
  swaps.follow(*scene, [&](int part) { refitted.push_back(part); });
  EXPECT_EQ(refitted, (std::vector<int>{0, 1, 2, 3, 4}));
  refitted.clear();
  scene->publish(3, exact);
  swaps.follow(*scene, [&](int part) { refitted.push_back(part); });
  EXPECT_EQ(refitted, std::vector<int>{3});
}

// A fingertip in the corner of a part's box, outside the part: the stand-in answers it is
// inside; once the part's own model is published, the next tick lets it go.
TEST(Scene, AGraspFeelsTheNewModelFromTheNextTick) {
  const auto scene = coarseScene(1);
  TwoFingerGrasp grasp(scene);
  HandSample hand;
  hand.index = Vec3(0.018, 0.018, 0.0);  // in the box, 5 mm outside the cylinder
  hand.thumb = Vec3(0.5, 0, 0);
  hand.wrist = Vec3(0.3, 0, 0.1);
  GraspOutput out = grasp.step(hand, 0.0005);
  EXPECT_EQ(out.indexPart, 0);
  EXPECT_GT(out.f_index.norm(), 0);
  scene->publish(0, makeScenePart(cylinder(), geometry::MassSpec::density(1000), {}));
  out = grasp.step(hand, 0.0005);
  EXPECT_EQ(out.indexPart, -1);
  EXPECT_EQ(out.f_index.norm(), 0);
}

// A stand-in box too small for the part (a shape's quick box can be): once the part's own
// model is in, the broad phase takes its bounds and the fingertip finds the part.
TEST(Scene, AModelWithLargerBoundsIsFoundWhereItReaches) {
  const geometry::Aabb small{Vec3::Constant(-0.002), Vec3::Constant(0.002)};
  const auto scene = std::make_shared<const Scene>(
      std::vector<ScenePart>{makeCoarseScenePart(small, geometry::MassSpec::density(1000), {})});
  TwoFingerGrasp grasp(scene);
  HandSample hand;
  hand.index = Vec3(0.015, 0, 0);  // 5 mm inside the cylinder, 13 mm beyond the stand-in
  hand.thumb = Vec3(0.5, 0, 0);
  hand.wrist = Vec3(0.3, 0, 0.1);
  EXPECT_EQ(grasp.step(hand, 0.0005).indexPart, -1);
  scene->publish(0, makeScenePart(cylinder(), geometry::MassSpec::density(1000), {}));
  const GraspOutput out = grasp.step(hand, 0.0005);
  EXPECT_EQ(out.indexPart, 0);
  EXPECT_GT(out.f_index.norm(), 0);
}

TEST(Scene, ReadersSeeWholeModelsWhilePublishersSwapThem) {
  const auto scene = coarseScene(4);
  const ScenePart exact = makeScenePart(cylinder(), geometry::MassSpec::density(1000), {});
  std::atomic<bool> stop{false};
  std::thread publisher([&] {
    for (int k = 0; k < 20000 && !stop; ++k) scene->publish(k % 4, k % 2 ? exact : makeCoarseScenePart(kBox, geometry::MassSpec::density(1000), {}));
  });
  long checked = 0;
  while (checked < 200000) {
    const ScenePart& p = scene->part(static_cast<std::size_t>(checked % 4));
    ASSERT_TRUE(p.penetration);
    ASSERT_GT(p.mass.mass_kg, 0);
    ASSERT_EQ(p.penetration->name() == "box", p.coarse);
    ++checked;
  }
  stop = true;
  publisher.join();
}

}  // namespace
}  // namespace hg::grasp
