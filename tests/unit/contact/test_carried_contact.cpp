// Carried contact over a grasp scene: a lifted part stops at another, is put down where it
// stopped, a part without a shell passes through and is counted, the scene's model swaps
// are taken in, slots run out cleanly, and nothing allocates after construction.
#include <gtest/gtest.h>

#include <algorithm>

#include "alloc_counter.hpp"
#include "contact/contact_fixtures.hpp"
#include "hapticgrasp/contact/carried_contact.hpp"

namespace hg::contact {
namespace {

grasp::ScenePart scenePart(const ContactModelPtr& model, const grasp::PartPose& pose, bool withShell = true) {
  grasp::ScenePart p = grasp::makeScenePart(model->partPtr(), geometry::MassSpec::mass(0.1), pose);
  if (withShell) p.contact = model;
  return p;
}

// A 10 mm cube at the origin and a plate whose top is 5 mm below it.
std::vector<grasp::ScenePart> cubeOverPlate(bool cubeShell = true, bool plateShell = true) {
  std::vector<grasp::ScenePart> parts;
  parts.push_back(scenePart(test::boxModel(0, 0, 0, 10, 10, 10), {}, cubeShell));
  parts.push_back(scenePart(test::boxModel(-20, -20, -10, 50, 50, 5), {}, plateShell));
  return parts;
}

CarriedContactConfig config(int slots = 1) {
  CarriedContactConfig c;
  c.query.maxPoints = 1024;
  c.slots = slots;
  return c;
}

// Carries part 0 from where it stands down by `depth` (m) over `ticks`; returns the last answer.
const CouplingOutput* lower(CarriedContact& contact, double depth, int ticks = 200) {
  const CouplingOutput* out = nullptr;
  for (int k = 1; k <= ticks; ++k) {
    contact.beginTick();
    out = contact.carry(0, test::poseAt(Vec3(0, 0, -depth * k / ticks)), 5e-4);
  }
  return out;
}

TEST(CarriedContact, ALiftedPartStopsOnAnotherAndIsPutDownThere) {
  CarriedContact contact(std::make_shared<const grasp::Scene>(cubeOverPlate()), config());
  ASSERT_TRUE(contact.lift(0, {}));
  EXPECT_TRUE(contact.carrying(0));
  const long before = test::allocations();
  const CouplingOutput* out = lower(contact, 0.008);  // 3 mm past the plate's top
  EXPECT_EQ(test::allocations() - before, 0);
  ASSERT_NE(out, nullptr);
  EXPECT_NEAR(out->pose.position.z(), -0.005, 5e-5);
  EXPECT_GT(out->force_N.z(), 2000 * 0.003 * 0.9);  // the coupling holds the hand up
  const ContactReport& r = contact.report();
  EXPECT_EQ(r.part, 0);
  EXPECT_EQ(r.otherPart, 1);
  EXPECT_EQ(r.carried, 1);
  EXPECT_TRUE(r.clearanceExact);
  EXPECT_LE(r.penetration_m, 5e-5);
  contact.putDown(0, out->pose);
  EXPECT_FALSE(contact.carrying(0));
  EXPECT_EQ(contact.scene().body(0).pose.position, out->pose.position);
  contact.beginTick();
  EXPECT_EQ(contact.carry(0, {}, 5e-4), nullptr);  // no longer carried
}

TEST(CarriedContact, APartWithoutAShellPassesThroughAndIsCounted) {
  CarriedContact contact(std::make_shared<const grasp::Scene>(cubeOverPlate(false)), config());
  EXPECT_FALSE(contact.lift(0, {}));
  contact.beginTick();
  EXPECT_EQ(contact.carry(0, test::poseAt(Vec3(0, 0, -0.008)), 5e-4), nullptr);
  EXPECT_EQ(contact.report().unmodelled, 1);
  EXPECT_EQ(contact.report().part, -1);
}

TEST(CarriedContact, AShellPublishedLaterIsMet) {
  std::vector<grasp::ScenePart> parts = cubeOverPlate(true, false);
  const ContactModelPtr plate = test::boxModel(-20, -20, -10, 50, 50, 5);
  auto scene = std::make_shared<const grasp::Scene>(std::move(parts));
  CarriedContact contact(scene, config());
  ASSERT_TRUE(contact.lift(0, {}));
  EXPECT_LT(lower(contact, 0.008)->pose.position.z(), -0.0075);  // through the plate without a shell
  contact.putDown(0, {});
  scene->publish(1, scenePart(plate, {}));  // the plate's exact models came, with its shell
  ASSERT_TRUE(contact.lift(0, {}));
  EXPECT_NEAR(lower(contact, 0.008)->pose.position.z(), -0.005, 5e-5);
}

// A press fit, or solids that overlap in the model: the cube lifted with its bottom 3 mm into
// the plate is let through by the plate (else it would be stuck fast), and still stopped
// by a wall it did not touch.
TEST(CarriedContact, APartLiftedInInterferenceIsLetThroughByThatPartOnly) {
  std::vector<grasp::ScenePart> parts;
  parts.push_back(scenePart(test::boxModel(0, 0, 0, 10, 10, 10), {}));
  parts.push_back(scenePart(test::boxModel(-20, -20, -2, 50, 50, 5), {}));  // overlaps the cube's bottom
  parts.push_back(scenePart(test::boxModel(15, -20, -10, 5, 50, 40), {}));  // a wall 5 mm to its +x
  CarriedContact contact(std::make_shared<const grasp::Scene>(std::move(parts)), config());
  ASSERT_TRUE(contact.lift(0, {}));
  const CouplingOutput* out = nullptr;
  for (int k = 1; k <= 200; ++k) {  // 4 mm down, then 8 mm to +x (down along the wall, friction would hold it)
    contact.beginTick();
    const double down = std::min(k, 100) / 100.0, across = std::max(k - 100, 0) / 100.0;
    out = contact.carry(0, test::poseAt(Vec3(0.008 * across, 0, -0.004 * down)), 5e-4);
  }
  ASSERT_NE(out, nullptr);
  EXPECT_EQ(contact.report().letThrough, 1);
  EXPECT_NEAR(out->pose.position.x(), 0.005, 5e-5);  // stopped by the wall
  EXPECT_NEAR(out->pose.position.z(), -0.004, 1e-6);  // through the plate
  EXPECT_EQ(contact.report().otherPart, 2);
  contact.putDown(0, out->pose);
  ASSERT_TRUE(contact.lift(0, test::poseAt(Vec3(0.005, 0, 0.02))));  // lifted clear of both
  contact.beginTick();
  contact.carry(0, test::poseAt(Vec3(0.005, 0, 0.02)), 5e-4);
  EXPECT_EQ(contact.report().letThrough, 0);
}

TEST(CarriedContact, SlotsRunOutCleanly) {
  std::vector<grasp::ScenePart> parts = cubeOverPlate();
  parts.push_back(scenePart(test::boxModel(40, 0, 0, 10, 10, 10), {}));
  CarriedContact contact(std::make_shared<const grasp::Scene>(std::move(parts)), config(1));
  EXPECT_TRUE(contact.lift(0, {}));
  EXPECT_FALSE(contact.lift(2, {}));  // one slot, taken
  contact.putDown(0, {});
  EXPECT_TRUE(contact.lift(2, {}));
  EXPECT_FALSE(contact.lift(7, {}));  // no such part
  EXPECT_THROW(CarriedContact(nullptr, config()), std::invalid_argument);
  EXPECT_THROW(CarriedContact(std::make_shared<const grasp::Scene>(cubeOverPlate()), config(0)), std::invalid_argument);
}

}  // namespace
}  // namespace hg::contact
