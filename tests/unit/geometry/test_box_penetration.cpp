// The coarse stand-in: a part's bounding box in closed form. It must answer as the exact
// answer for a real box does, and its mass be the box's.
#include "hapticgrasp/geometry/box_penetration.hpp"

#include <BRepPrimAPI_MakeBox.hxx>
#include <gtest/gtest.h>

#include <random>

#include "alloc_counter.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::geometry {
namespace {

const Aabb kBox{Vec3(-0.02, -0.01, 0.0), Vec3(0.04, 0.01, 0.005)};  // 60 x 20 x 5 mm

TEST(BoxPenetration, AgreesWithTheExactBackEndOnARealBox) {
  const auto part = PartModel::fromShape(BRepPrimAPI_MakeBox(gp_Pnt(-20, -10, 0), 60, 20, 5).Shape(),
                                         LengthUnit::Millimetre, "box");
  const auto exact = makeExactPenetration(part);
  const BoxPenetration box(kBox);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  int inside = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec3 x = kBox.centre() + Vec3(4 * u(rng), 2 * u(rng), 0.6 * u(rng));
    QueryState a, b;
    const Penetration pe = exact->query(x, a), pb = box.query(x, b);
    ASSERT_EQ(pb.inside, pe.inside) << x.transpose();
    ASSERT_NEAR(pb.depth, pe.depth, 1e-12) << x.transpose();
    ASSERT_LT((pb.foot - pe.foot).norm(), 1e-9) << x.transpose();
    if (pe.distance() > 1e-6) ASSERT_LT((pb.normal - pe.normal).norm(), 1e-6) << x.transpose();
    ASSERT_LT((pb.vector - (x - pb.foot)).norm(), 1e-15);
    inside += pb.inside;
  }
  EXPECT_GT(inside, 500);
  EXPECT_LT(inside, 4500);
}

TEST(BoxPenetration, NamesTheFeatureAndHoldsAFaceAsAGodObjectAsks) {
  const BoxPenetration box(kBox);
  QueryState s;
  Penetration p = box.query(Vec3(0.039, 0, 0.0025), s);  // just inside +x
  EXPECT_TRUE(p.inside);
  EXPECT_EQ(p.feature, Feature::Face);
  EXPECT_EQ(p.featureIndex, 2);
  EXPECT_NEAR(p.depth, 0.001, 1e-12);
  EXPECT_EQ(box.query(Vec3(0.05, 0.02, 0.0025), s).feature, Feature::Edge);
  EXPECT_EQ(box.query(Vec3(0.05, 0.02, 0.01), s).feature, Feature::Vertex);
  // Against the +z face only, from inside near -x: the face's depth, not the nearer -x face's.
  Penetration f;
  double uu = 0, vv = 0;
  ASSERT_TRUE(box.againstFeature(Vec3(-0.0195, 0, 0.001), Feature::Face, 6, uu, vv, f));
  EXPECT_NEAR(f.depth, 0.004, 1e-12);
  EXPECT_EQ(f.normal, Vec3::UnitZ());
  EXPECT_FALSE(box.againstFeature(Vec3(0.05, 0, 0.001), Feature::Face, 6, uu, vv, f));  // beyond the face
  EXPECT_FALSE(box.againstFeature(Vec3(0, 0, 0.001), Feature::Edge, 1, uu, vv, f));
}

TEST(BoxPenetration, MassIsTheBoxs) {
  const BoxPenetration box(kBox);
  const MassProperties m = box.massProperties(MassSpec::density(1000));
  EXPECT_NEAR(m.volume_m3, 0.06 * 0.02 * 0.005, 1e-15);
  EXPECT_NEAR(m.mass_kg, 6.0e-3, 1e-12);
  EXPECT_LT((m.centre_m - kBox.centre()).norm(), 1e-15);
  EXPECT_NEAR(m.inertia_kgm2(2, 2), 6.0e-3 / 12 * (0.06 * 0.06 + 0.02 * 0.02), 1e-15);
  EXPECT_NEAR(box.massProperties(MassSpec::mass(2)).mass_kg, 2, 0);
  EXPECT_EQ(box.setting(), "bounding box 60 x 20 x 5 mm");
}

TEST(BoxPenetration, RefusesAnEmptyBoxAndAllocatesNothing) {
  EXPECT_THROW(BoxPenetration(Aabb{}), GeometryError);
  const BoxPenetration box(kBox);
  QueryState s;
  const long before = test::allocations();
  double sum = 0;
  for (int i = 0; i < 1000; ++i) sum += box.query(Vec3(1e-5 * i, 0, 0.001), s).depth;
  EXPECT_EQ(test::allocations() - before, 0);
  EXPECT_GT(sum, 0);
}

}  // namespace
}  // namespace hg::geometry
