// The constraint solver stops a part at a contact, pushes an interpenetrating one out,
// holds it by friction below the cone and lets it slide beyond it, turns it where one
// corner is caught, and gives the contact forces in newtons.
#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "hapticgrasp/contact/constraint_solver.hpp"

namespace hg::contact {
namespace {

Contact floorContact(const Vec3& point, double gap) {
  Contact c;
  c.point = point;
  c.normal = Vec3::UnitZ();
  c.gap = gap;
  return c;
}

Vec6 move(const Vec3& t, const Vec3& r = Vec3::Zero()) {
  Vec6 v;
  v << t, r;
  return v;
}

TEST(ConstraintSolver, StopsAtTheFloorAndBalancesThePull) {
  ConstraintSolver solver;
  const CouplingStiffness k{2000, 5};
  // Four corners of a 20 mm square, 0.1 mm above the floor; the hand asks for 1 mm down.
  std::vector<Contact> corners;
  for (double x : {-0.01, 0.01})
    for (double y : {-0.01, 0.01}) corners.push_back(floorContact(Vec3(x, y, 0), 1e-4));
  const ConstraintSolution& s = solver.solve(move(Vec3(0, 0, -1e-3)), corners, Vec3(0, 0, 0.005), k, 0.3, 50);
  EXPECT_NEAR(s.displacement(2), -1e-4, 1e-7);            // Gauss-Seidel's residual: 0.1 um
  EXPECT_NEAR(s.displacement.tail<3>().norm(), 0, 1e-5);  // rad: four corners balance it
  // The floor carries the spring's pull: k (1 mm - 0.1 mm) = 1.8 N.
  EXPECT_NEAR(s.normalForce_N, 1.8, 1e-3);
  EXPECT_NEAR(s.force_N.z(), 1.8, 1e-3);
}

TEST(ConstraintSolver, PushesAnInterpenetratingPartOut) {
  ConstraintSolver solver;
  const std::vector<Contact> c{floorContact(Vec3::Zero(), -2e-5)};
  const ConstraintSolution& s = solver.solve(Vec6::Zero(), c, Vec3(0, 0, 0.01), {2000, 1e6}, 0, 20);
  EXPECT_NEAR(s.displacement(2), 2e-5, 1e-9);
}

TEST(ConstraintSolver, FrictionHoldsInsideTheConeAndSlidesOutsideIt) {
  ConstraintSolver solver;
  const CouplingStiffness k{2000, 1e6};  // stiff in rotation: translation only
  const std::vector<Contact> c{floorContact(Vec3::Zero(), 0)};
  // Down 1 mm (2 N normal), sideways 0.1 mm (0.2 N < 0.3 x 2 N): it sticks.
  EXPECT_NEAR(solver.solve(move(Vec3(1e-4, 0, -1e-3)), c, Vec3(0, 0, 0.01), k, 0.3, 50).displacement(0), 0, 1e-9);
  // Sideways 1 mm (2 N > 0.6 N): it slides until the spring's lag carries 0.6 N, 0.3 mm.
  const ConstraintSolution& s = solver.solve(move(Vec3(1e-3, 0, -1e-3)), c, Vec3(0, 0, 0.01), k, 0.3, 50);
  EXPECT_NEAR(s.displacement(0), 1e-3 - 0.3 * 1e-3, 1e-7);
  EXPECT_NEAR(-s.force_N.x(), 0.3 * s.force_N.z(), 1e-6);
}

TEST(ConstraintSolver, TurnsAPartCaughtAtOneCorner) {
  ConstraintSolver solver;
  const std::vector<Contact> c{floorContact(Vec3(0.01, 0, 0), 0)};
  const ConstraintSolution& s = solver.solve(move(Vec3(0, 0, -1e-3)), c, Vec3::Zero(), {2000, 0.2}, 0, 100);
  EXPECT_LT(s.displacement(2), -1e-4);                                 // the centre goes on down
  EXPECT_LT(s.displacement(4), 0);                                     // it turns about y ...
  EXPECT_NEAR(s.displacement(2) - 0.01 * s.displacement(4), 0, 1e-7);  // ... keeping the corner on the floor
}

TEST(ConstraintSolver, AllocatesNothing) {
  ConstraintSolver solver(64);
  std::vector<Contact> c(64, floorContact(Vec3(0.01, 0, 0), 1e-5));
  const long before = test::allocations();
  for (int k = 0; k < 100; ++k) solver.solve(move(Vec3(0, 0, -1e-3)), c, Vec3::Zero(), {2000, 1}, 0.3, 30);
  EXPECT_EQ(test::allocations() - before, 0);
}

}  // namespace
}  // namespace hg::contact
