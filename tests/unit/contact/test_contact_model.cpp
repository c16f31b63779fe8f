// The contact model's shell lies on the exact surface with outward normals, keeps within
// its budget, samples every face, and finds sharp convex edges only (a box's twelve; not a
// cylinder's seam, nor a step's inside corner).
#include <gtest/gtest.h>

#include <set>

#include "contact/contact_fixtures.hpp"
#include "hapticgrasp/contact/contact_model.hpp"

namespace hg::contact {
namespace {

void expectOnSurfaceWithOutwardNormals(const ContactModel& model, double tolerance_m) {
  for (const ShellPoint& p : model.shell()) {
    geometry::QueryState state;
    const geometry::Penetration q = model.penetration().query(p.position, state);
    ASSERT_LT(q.distance(), tolerance_m) << p.position.transpose();
    ASSERT_NEAR(p.normal.norm(), 1.0, 1e-9);
    // A little way out along the normal is outside, a little way in is inside.
    EXPECT_FALSE(model.penetration().query(p.position + 1e-4 * p.normal, state).inside) << p.position.transpose();
  }
}

TEST(ContactModel, ABoxsShellLiesOnItsFacesAndAlongItsTwelveEdges) {
  const ContactModelPtr box = test::boxModel(0, 0, 0, 100, 60, 30, 1000);
  EXPECT_LE(box->shell().size(), 1000u);
  EXPECT_GT(box->shell().size(), 800u);
  EXPECT_EQ(box->sharpEdgeCount(), 12);
  std::set<int> faces, edges;
  for (const ShellPoint& p : box->shell()) faces.insert(p.face);
  for (const ShellPoint& p : box->sharpEdges()) edges.insert(p.edge);
  EXPECT_EQ(faces.size(), 6u);
  EXPECT_EQ(edges.size(), 12u);
  expectOnSurfaceWithOutwardNormals(*box, 1e-9);
  // Edge points lie closer together than face points (edgeDensity), corners included.
  int corners = 0;
  for (const ShellPoint& p : box->sharpEdges()) {
    const Vec3 mm = p.position * 1e3;
    if ((mm.array().abs() < 1e-6 || (mm - Vec3(100, 60, 30)).array().abs() < 1e-6).all()) ++corners;
  }
  EXPECT_GT(corners, 0);
  EXPECT_NEAR(box->radius(), Vec3(0.05, 0.03, 0.015).norm(), 1e-9);
}

TEST(ContactModel, ACylindersSeamIsNotSharpButItsRimsAre) {
  const ContactModelPtr peg = test::pegModel(400);
  EXPECT_EQ(peg->sharpEdgeCount(), 2);  // the two rims; the seam has one face on both sides
  expectOnSurfaceWithOutwardNormals(*peg, 1e-9);
}

TEST(ContactModel, AHolesConcaveEdgesAreLeftOutAndSmallFacesKept) {
  const ContactModelPtr block = test::holeBlockModel();
  // Convex: the box's 12 edges and the chamfer's top rim; the chamfer's lower rim (135 deg,
  // convex) too. Concave: none in this part, and a 45 deg chamfer is sharp at 29 deg.
  EXPECT_GE(block->sharpEdgeCount(), 14);
  std::set<int> faces;
  for (const ShellPoint& p : block->shell()) faces.insert(p.face);
  EXPECT_EQ(static_cast<int>(faces.size()), block->part().faces().Extent());  // the small chamfer too
  expectOnSurfaceWithOutwardNormals(*block, 1e-8);

  // A step: its inside corner is concave and has no edge points.
  TopoDS_Shape step = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 40, 20, 10).Shape();
  step = BRepAlgoAPI_Cut(step, BRepPrimAPI_MakeBox(gp_Pnt(20, -1, 5), 30, 22, 10).Shape()).Shape();
  const ContactModelPtr stepped = test::contactModelOf(step, "step");
  for (const ShellPoint& p : stepped->sharpEdges()) {
    const Vec3 mm = p.position * 1e3;
    // Along the inside corner (its ends are also the ends of convex edges: corners).
    EXPECT_FALSE(std::abs(mm.x() - 20) < 1e-6 && std::abs(mm.z() - 5) < 1e-6 && mm.y() > 1e-3 && mm.y() < 20 - 1e-3)
        << "concave edge sampled";
  }
}

TEST(ContactModel, KeepsToItsBudgetWhenSmallFeaturesAloneExceedIt) {
  // 64 holes: 64 cylinder faces and 128 sharp rims, each with its minimum of points.
  TopoDS_Shape plate = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 80, 80, 2).Shape();
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      plate = BRepAlgoAPI_Cut(
                  plate,
                  BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(5 + 10 * i, 5 + 10 * j, -1), gp_Dir(0, 0, 1)), 1, 4).Shape())
                  .Shape();
  const ContactModelPtr model = test::contactModelOf(plate, "perforated", 200);
  EXPECT_EQ(model->shell().size(), 200u);
  EXPECT_GT(model->sharpEdges().size(), 0u);
  EXPECT_LT(model->sharpEdges().size(), 200u);
}

TEST(ContactModel, RefusesWhatItCannotModel) {
  const ContactModelPtr peg = test::pegModel();
  EXPECT_THROW(ContactModel::build(nullptr, nullptr), std::invalid_argument);
  ContactModelOptions tiny;
  tiny.maxPoints = 4;
  EXPECT_THROW(ContactModel::build(peg->partPtr(), geometry::makePenetration(peg->partPtr()), tiny),
               std::invalid_argument);
}

}  // namespace
}  // namespace hg::contact
