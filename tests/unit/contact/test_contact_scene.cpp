// The contact scene answers which parts a box overlaps, leaves out the carried part, and
// follows a part put down elsewhere and a part whose model came later.
#include <gtest/gtest.h>

#include <algorithm>

#include "alloc_counter.hpp"
#include "contact/contact_fixtures.hpp"
#include "hapticgrasp/contact/contact_scene.hpp"

namespace hg::contact {
namespace {

std::vector<int> near(const ContactScene& scene, const geometry::Aabb& box, int exclude) {
  std::vector<int> out(scene.size());
  out.resize(scene.nearby(box, exclude, out));
  std::sort(out.begin(), out.end());
  return out;
}

TEST(ContactScene, FindsThePartsABoxOverlapsButTheCarriedOne) {
  const ContactModelPtr cube = test::boxModel(0, 0, 0, 10, 10, 10);
  std::vector<ContactBody> bodies;
  for (int i = 0; i < 5; ++i) bodies.push_back({cube, test::poseAt(Vec3(0.02 * i, 0, 0))});
  ContactScene scene(bodies);
  const geometry::Aabb around{Vec3(0.015, 0.001, 0.001), Vec3(0.045, 0.002, 0.002)};
  EXPECT_EQ(near(scene, around, -1), (std::vector<int>{1, 2}));
  EXPECT_EQ(near(scene, around, 1), (std::vector<int>{2}));
  const std::uint64_t before = scene.revision(4), other = scene.revision(1);
  const long allocations = test::allocations();
  scene.setPose(4, test::poseAt(Vec3(0.03, 0, 0)));
  EXPECT_EQ(test::allocations() - allocations, 0);
  EXPECT_GT(scene.revision(4), before);
  EXPECT_EQ(scene.revision(1), other);  // a part's move leaves the others' cached answers valid
  EXPECT_EQ(near(scene, around, -1), (std::vector<int>{1, 2, 4}));
}

TEST(ContactScene, APartWithoutAModelIsNeverNearUntilItGetsOne) {
  const ContactModelPtr cube = test::boxModel(0, 0, 0, 10, 10, 10);
  ContactScene scene({ContactBody{nullptr, test::poseAt(Vec3(0, 0, 0))}, ContactBody{cube, test::poseAt(Vec3(0.02, 0, 0))}});
  const geometry::Aabb everywhere{Vec3::Constant(-1), Vec3::Constant(1)};
  EXPECT_EQ(near(scene, everywhere, -1), (std::vector<int>{1}));
  const std::uint64_t before = scene.revision(0);
  const long allocations = test::allocations();
  scene.setModel(0, cube);  // its exact models came
  EXPECT_EQ(test::allocations() - allocations, 0);
  EXPECT_GT(scene.revision(0), before);  // answers about it are stale
  EXPECT_EQ(near(scene, everywhere, -1), (std::vector<int>{0, 1}));
  EXPECT_EQ(near(scene, geometry::Aabb{Vec3::Constant(0.001), Vec3::Constant(0.002)}, -1), (std::vector<int>{0}));
  scene.setModel(1, nullptr);
  EXPECT_EQ(near(scene, everywhere, -1), (std::vector<int>{0}));
}

}  // namespace
}  // namespace hg::contact
