// The contact scene answers which parts a box overlaps, leaves out the carried part, and
// follows a part put down elsewhere.
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
  EXPECT_THROW(ContactScene({ContactBody{}}), std::invalid_argument);
}

}  // namespace
}  // namespace hg::contact
