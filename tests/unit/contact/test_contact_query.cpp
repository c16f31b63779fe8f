// The narrow phase finds face-on-face and edge-on-face contacts both ways with the right
// normals, says the clearance and which faces, and the depth of an interference; at rest
// it queries nothing again; it never allocates.
#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>

#include "alloc_counter.hpp"
#include "contact/contact_fixtures.hpp"
#include "hapticgrasp/contact/contact_query.hpp"

namespace hg::contact {
namespace {

constexpr double kMargin = 2.5e-4;

// A floor 100 x 100 x 20 mm, its top at z = 0.
ContactScene floorScene() { return test::sceneOf({test::boxModel(-50, -50, -20, 100, 100, 20)}); }

double smallestGap(std::span<const Contact> contacts) {
  double g = 1;
  for (const Contact& c : contacts) g = std::min(g, c.gap);
  return g;
}

TEST(ContactQuery, FindsAFaceOnAFaceWithTheOtherPartsNormalAndFaces) {
  const ContactScene scene = floorScene();
  ContactQuery query(test::boxModel(-5, -5, 0, 10, 10, 10, 400));
  const auto contacts = query.run(test::poseAt(Vec3(0, 0, 1e-4)), scene, -1, kMargin);
  ASSERT_GT(contacts.size(), 20u);
  int onBottom = 0;
  for (const Contact& c : contacts) {  // the bottom face's points, and the sides' lowest ones
    EXPECT_GE(c.gap, 1e-4 - 1e-9);
    if (c.gap < 1e-4 + 1e-9) ++onBottom;
    EXPECT_NEAR(c.normal.z(), 1, 1e-9);
    EXPECT_EQ(c.part, 0);
  }
  EXPECT_GT(onBottom, 20);
  const Clearance& clear = query.clearance();
  EXPECT_TRUE(clear.exact);
  EXPECT_NEAR(clear.distance_m, 1e-4, 1e-9);
  // The cube's bottom face (z = 0 in its frame) against the floor's top face.
  const TopoDS_Face& bottom = TopoDS::Face(query.held().part().faces().FindKey(clear.heldFace));
  EXPECT_NEAR(BRepAdaptor_Surface(bottom).Value(0, 0).Z(), 0, 1e-9);
  EXPECT_NEAR(
      BRepAdaptor_Surface(TopoDS::Face(scene.body(0).model->part().faces().FindKey(clear.otherFace))).Value(0, 0).Z(),
      0, 1e-9);
}

TEST(ContactQuery, FindsTheCarriedPartsEdgeOnAFace) {
  const ContactScene scene = floorScene();
  ContactQuery query(test::boxModel(-5, -5, -5, 10, 10, 10, 400));
  // Turned 45 deg about x: its lowest edge, 5 sqrt 2 mm below its centre, 0.05 mm into the floor.
  const double h = 5e-3 * std::numbers::sqrt2 - 5e-5;
  const auto contacts = query.run(test::poseAt(Vec3(0, 0, h), std::numbers::pi / 4), scene, -1, kMargin);
  ASSERT_FALSE(contacts.empty());
  EXPECT_NEAR(smallestGap(contacts), -5e-5, 1e-8);
  const auto deepest =
      std::min_element(contacts.begin(), contacts.end(), [](auto& a, auto& b) { return a.gap < b.gap; });
  EXPECT_FALSE(deepest->otherEdge);
  EXPECT_NEAR(deepest->normal.z(), 1, 1e-9);
  EXPECT_LT(query.clearance().distance_m, 0);  // in interference, by the depth
}

TEST(ContactQuery, FindsAnotherPartsEdgeOnTheCarriedPartsFace) {
  // A ridge: a 10 mm bar turned 45 deg about x, its top edge at z = 0, under a wide plate
  // whose face points lie 6 mm apart: the edge falls between them.
  TopoDS_Shape bar = BRepPrimAPI_MakeBox(gp_Pnt(-20, -5, -5), 40, 10, 10).Shape();
  gp_Trsf turn;
  turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)), std::numbers::pi / 4);
  gp_Trsf lift;
  lift.SetTranslation(gp_Vec(0, 0, -5 * std::numbers::sqrt2));
  bar = BRepBuilderAPI_Transform(BRepBuilderAPI_Transform(bar, turn).Shape(), lift).Shape();
  const ContactScene scene = test::sceneOf({test::contactModelOf(bar, "ridge")});
  const ContactModelPtr plate = test::boxModel(-30, -30, 0, 60, 60, 5, 200);
  ASSERT_GT(plate->spacing_m(), 4e-3);
  ContactQuery query(plate);
  const auto contacts = query.run(test::poseAt(Vec3(0.0011, 0.0013, -3e-5)), scene, -1, kMargin);
  const auto fromEdge = std::count_if(contacts.begin(), contacts.end(), [](const Contact& c) {
    return c.otherEdge && c.gap < -2e-5 && c.normal.z() > 0.999;
  });
  EXPECT_GT(fromEdge, 3);
  EXPECT_NEAR(smallestGap(contacts), -3e-5, 1e-8);
}

TEST(ContactQuery, SaysTheClearanceWithinRangeAndABoundBeyondIt) {
  const ContactScene scene = floorScene();
  ContactQueryConfig config;
  config.clearanceRange_m = 5e-3;
  ContactQuery near(test::boxModel(-5, -5, 0, 10, 10, 10, 400), config);
  EXPECT_TRUE(near.run(test::poseAt(Vec3(0, 0, 3e-3)), scene, -1, kMargin).empty());
  EXPECT_TRUE(near.clearance().exact);
  EXPECT_NEAR(near.clearance().distance_m, 3e-3, 1e-9);
  EXPECT_EQ(near.clearance().part, 0);
  ContactQuery far(test::boxModel(-5, -5, 0, 10, 10, 10, 400));
  far.run(test::poseAt(Vec3(0, 0, 3e-3)), scene, -1, kMargin);
  EXPECT_FALSE(far.clearance().exact);  // no part's box within range: nothing nearer than that
  EXPECT_GT(far.clearance().distance_m, kMargin);
  // Within another part's box, but no point within range: a bound, at most the truth. A
  // 4 mm cube in the middle of the 10.1 mm hole: its corners 5.05 - 2 sqrt 2 mm from the wall.
  const ContactScene hole = test::sceneOf({test::holeBlockModel(0.1)});
  ContactQuery cube(test::boxModel(-2, -2, -2, 4, 4, 4, 400));
  EXPECT_TRUE(cube.run(test::poseAt(Vec3(0, 0, -0.01)), hole, -1, kMargin).empty());
  EXPECT_FALSE(cube.clearance().exact);
  EXPECT_GT(cube.clearance().distance_m, kMargin);
  EXPECT_LE(cube.clearance().distance_m, 5.05e-3 - 2e-3 * std::numbers::sqrt2 + 1e-9);
}

TEST(ContactQuery, APartPutDownElsewhereIsAnsweredWhereItIsNow) {
  ContactScene scene = floorScene();
  ContactQuery query(test::boxModel(-5, -5, 0, 10, 10, 10, 400));
  const grasp::PartPose at = test::poseAt(Vec3(0, 0, 1e-4));
  EXPECT_NEAR(smallestGap(query.run(at, scene, -1, kMargin)), 1e-4, 1e-9);
  scene.setPose(0, test::poseAt(Vec3(0, 0, 2e-4)));  // the floor raised 0.2 mm under it
  EXPECT_NEAR(smallestGap(query.run(at, scene, -1, kMargin)), -1e-4, 1e-9);
  EXPECT_NEAR(query.clearance().distance_m, -1e-4, 1e-9);  // in interference, by that much
}

TEST(ContactQuery, KeepsTheSmallestGapsWhenThereAreMoreContactsThanRoom) {
  const ContactScene scene = floorScene();
  ContactQueryConfig config;
  config.maxContacts = 10;
  ContactQuery query(test::boxModel(-5, -5, 0, 10, 10, 10, 400), config);
  // Tilted 1 deg about y: the bottom face's gaps spread from 0 to 0.17 mm along x.
  const auto contacts = query.run(
      test::poseAt(Vec3(0, 0, 1e-5 + 5e-3 * std::sin(std::numbers::pi / 180)), std::numbers::pi / 180, Vec3::UnitY()),
      scene, -1, kMargin);
  ASSERT_EQ(contacts.size(), 10u);
  EXPECT_GT(query.stats().contacts, 10);
  double largestKept = 0;
  for (const Contact& c : contacts) largestKept = std::max(largestKept, c.gap);
  EXPECT_NEAR(smallestGap(contacts), query.clearance().distance_m, 1e-12);
  EXPECT_LT(largestKept, 5e-5);  // the low edge's, not the face's far side
}

TEST(ContactQuery, AtRestQueriesNothingAgainAndAllocatesNothing) {
  const ContactScene scene = floorScene();
  ContactQuery query(test::boxModel(-5, -5, 0, 10, 10, 10, 400));
  const auto first = query.run(test::poseAt(Vec3(0, 0, 1e-4)), scene, -1, kMargin);
  const std::size_t count = first.size();
  EXPECT_GT(query.stats().queried, 0);
  const long before = test::allocations();
  const auto again = query.run(test::poseAt(Vec3(0, 0, 1e-4)), scene, -1, kMargin);
  EXPECT_EQ(query.stats().queried, 0);
  EXPECT_EQ(again.size(), count);
  for (int k = 0; k < 200; ++k) query.run(test::poseAt(Vec3(1e-5 * k, 0, 1e-4)), scene, -1, kMargin);
  EXPECT_EQ(test::allocations() - before, 0);
  EXPECT_GT(query.stats().queried + query.stats().predicted, 0);
}

}  // namespace
}  // namespace hg::contact
