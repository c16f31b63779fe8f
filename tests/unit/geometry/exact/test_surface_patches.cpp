// The patches of a freeform face: they tile its parameter box, their bounds hold every
// point of the surface they cover, and they are as flat and small as asked.
#include <gtest/gtest.h>

#include <BRepTools.hxx>

#include "geometry/exact/face_model.hpp"
#include "surface_fixtures.hpp"

namespace hg::geometry::exact {
namespace {

struct Wavy : ::testing::Test {
  TopoDS_Face face = test::wavyFace();
  FaceModel model{face, 80.0};
  double u0, u1, v0, v1;
  void SetUp() override { BRepTools::UVBounds(face, u0, u1, v0, v1); }
};

TEST_F(Wavy, PatchesTileTheParameterBox) {
  const auto& patches = model.patches();
  ASSERT_GT(patches.size(), 4u);
  double area = 0;
  for (std::size_t i = 0; i < patches.size(); ++i) {
    const UvRect& a = patches[i].rect;
    area += a.du() * a.dv();
    EXPECT_GE(a.u0, u0 - 1e-12);
    EXPECT_LE(a.u1, u1 + 1e-12);
    for (std::size_t j = i + 1; j < patches.size(); ++j) {
      const UvRect& b = patches[j].rect;
      const double ou = std::min(a.u1, b.u1) - std::max(a.u0, b.u0), ov = std::min(a.v1, b.v1) - std::max(a.v0, b.v0);
      EXPECT_FALSE(ou > 1e-12 && ov > 1e-12) << i << " overlaps " << j;
    }
  }
  EXPECT_NEAR(area, (u1 - u0) * (v1 - v0), 1e-9 * (u1 - u0) * (v1 - v0));
}

TEST_F(Wavy, BoundsHoldTheSurfaceTheyCover) {
  for (const SurfacePatch& p : model.patches()) {
    ASSERT_TRUE(p.bound.oriented());
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; j <= 20; ++j) {
        const double u = p.rect.u0 + p.rect.du() * i / 20, v = p.rect.v0 + p.rect.dv() * j / 20;
        const gp_Pnt q = model.value(u, v);
        EXPECT_EQ(p.bound.squaredDistance(Vec3(q.X(), q.Y(), q.Z())), 0.0) << u << " " << v;
      }
  }
}

TEST_F(Wavy, PatchesAreNearlyFlatAndSmallForTheirCurvature) {
  const PatchOptions asked;
  for (const SurfacePatch& p : model.patches()) {
    // The normal turns little from the seeds' mean over the patch.
    gp_Vec mean(0, 0, 0);
    for (const SurfaceJet& s : p.seeds) mean += s.du.Crossed(s.dv).Normalized();
    mean.Normalize();
    for (int i = 0; i <= 10; ++i)
      for (int j = 0; j <= 10; ++j) {
        gp_Pnt q;
        gp_Vec su, sv, suu, svv, suv;
        model.d2(p.rect.u0 + p.rect.du() * i / 10, p.rect.v0 + p.rect.dv() * j / 10, q, su, sv, suu, svv, suv);
        EXPECT_LT(mean.Angle(su.Crossed(sv)), 2.5 * asked.maxTurn_rad);
      }
    EXPECT_LE(p.spread * std::max(p.kTowards, p.kAway), 1.01 * asked.maxSpreadCurvature);
  }
}

TEST_F(Wavy, FarPointsAreNotClearOfFocusNearOnesAre) {
  // A patch on a bump: close above it a point has one foot on it, at the bump's centre of
  // curvature and beyond it need not.
  const SurfacePatch* bump = nullptr;
  for (const SurfacePatch& p : model.patches())
    if (std::max(p.kTowards, p.kAway) > 0.05) bump = &p;
  ASSERT_NE(bump, nullptr);
  const Vec3 c = bump->bound.centre, n = bump->bound.axes.col(2);
  const double k = std::max(bump->kTowards, bump->kAway);
  EXPECT_TRUE(bump->clearOfFocus(c + 0.1 / k * n, 0.1 / k));
  EXPECT_FALSE(bump->clearOfFocus(c + 2 / k * n, 2 / k) && bump->clearOfFocus(c - 2 / k * n, 2 / k));
}

}  // namespace
}  // namespace hg::geometry::exact
