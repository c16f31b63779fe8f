// The reduction keeps, of a face's hundred contacts, the deepest and the patch's extremes;
// of contacts with different normals, some of each; and allocates nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "alloc_counter.hpp"
#include "hapticgrasp/contact/contact_reduction.hpp"

namespace hg::contact {
namespace {

Contact at(const Vec3& point, const Vec3& normal, double gap) {
  Contact c;
  c.point = point;
  c.normal = normal.normalized();
  c.gap = gap;
  return c;
}

TEST(ContactReduction, AFlatPatchKeepsItsDeepestPointAndItsExtremes) {
  std::vector<Contact> in;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) in.push_back(at(Vec3(0.001 * i, 0.001 * j, 0), Vec3::UnitZ(), 1e-5 * (i + j + 1)));
  in[57].gap = -2e-5;  // the deepest, inside the patch
  std::vector<Contact> out(in.size());
  ContactReduction reduction;
  const std::size_t n = reduction.reduce(in, out);
  EXPECT_LE(n, 5u);
  EXPECT_GE(n, 3u);
  bool deepest = false;
  double minX = 1, maxX = -1, minY = 1, maxY = -1;
  for (std::size_t k = 0; k < n; ++k) {
    deepest |= out[k].gap == -2e-5;
    minX = std::min(minX, out[k].point.x()), maxX = std::max(maxX, out[k].point.x());
    minY = std::min(minY, out[k].point.y()), maxY = std::max(maxY, out[k].point.y());
  }
  EXPECT_TRUE(deepest);
  EXPECT_DOUBLE_EQ(minX, 0);
  EXPECT_DOUBLE_EQ(maxX, 0.009);
  EXPECT_DOUBLE_EQ(minY, 0);
  EXPECT_DOUBLE_EQ(maxY, 0.009);
}

TEST(ContactReduction, NormalsApartAreKeptApart) {
  // A peg's side: normals all around, 36 of them; a floor and a wall.
  std::vector<Contact> in;
  for (int k = 0; k < 36; ++k) {
    const double a = 2 * std::numbers::pi * k / 36;
    in.push_back(at(Vec3(0.005 * std::cos(a), 0.005 * std::sin(a), 0), Vec3(-std::cos(a), -std::sin(a), 0), 1e-5));
  }
  std::vector<Contact> out(in.size());
  ContactReduction reduction;
  const std::size_t n = reduction.reduce(in, out);
  EXPECT_GE(n, 12u);  // at least one a 30 deg sector
  EXPECT_LE(n, in.size());
  const std::vector<Contact> corner{at(Vec3::Zero(), Vec3::UnitZ(), 0), at(Vec3(0.01, 0, 0), Vec3::UnitZ(), 0),
                                    at(Vec3(0.01, 0, 0.01), -Vec3::UnitX(), 0)};
  EXPECT_EQ(reduction.reduce(corner, out), 3u);
  const long before = test::allocations();
  for (int k = 0; k < 100; ++k) reduction.reduce(in, out);
  EXPECT_EQ(test::allocations() - before, 0);
  EXPECT_EQ(reduction.reduce({}, out), 0u);
}

}  // namespace
}  // namespace hg::contact
