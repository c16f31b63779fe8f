// Both grasp methods with part-to-part contact: a block is grasped, lifted and lowered onto a
// plate. With contact it stops on the plate (and is put down there), the hand feels it (the
// two-finger wrist, the multi-finger fingertips), and the two-finger grasp force stays the
// grasp's; without contact the same hand takes it through the plate. No allocation.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "alloc_counter.hpp"
#include "contact/contact_fixtures.hpp"
#include "hapticgrasp/servo/grasp_engine.hpp"

namespace hg::servo {
namespace {

using grasp::GraspState;

using test::handAt;
using test::kMm;
using test::kPlateTop;
using test::lowerOntoPlate;
constexpr double kDt = 5e-4;

grasp::ScenePtr blockOverPlate(double mass_kg) { return test::blockOverPlate(mass_kg); }

struct Outcome {
  bool manipulated = false;
  double lowest = 1;              // the cube's lowest bottom while carried (world z, m)
  double restingBottom = 1;       // where it was put down
  EngineStep holding;             // at t = 1.45 s: lowered and held
  long allocations = -1;
  GraspState end = GraspState::Manipulate;
};

Outcome run(GraspEngine& engine, const std::vector<test::HandKey>& keys) {
  Outcome r;
  const long before = test::allocations();
  for (int tick = 0; tick * kDt <= 1.9; ++tick) {
    const double t = tick * kDt;
    const EngineStep s = engine.step(handAt(keys, t), tick == 0 ? 0.0 : kDt);
    if (engine.state() == GraspState::Manipulate) {
      r.manipulated = true;
      r.lowest = std::min(r.lowest, engine.poses()[0].position.z());
    }
    if (tick == static_cast<int>(1.45 / kDt)) r.holding = s;
  }
  r.allocations = test::allocations() - before;
  r.end = engine.state();
  r.restingBottom = engine.poses()[0].position.z();
  return r;
}

contact::CarriedContactConfig contactConfig() {
  contact::CarriedContactConfig c;
  c.query.maxPoints = 1024;
  return c;
}

TEST(TwoFingerEngineContact, TheBlockStopsOnThePlateAndTheWristFeelsIt) {
  const grasp::ScenePtr scene = blockOverPlate(0.1);
  TwoFingerEngine with(scene, {}, contactConfig()), without(scene);
  ASSERT_NE(with.contact(), nullptr);
  EXPECT_EQ(without.contact(), nullptr);
  const Outcome a = run(with, lowerOntoPlate(0.5));
  const Outcome b = run(without, lowerOntoPlate(0.5));
  ASSERT_TRUE(a.manipulated && b.manipulated);
  EXPECT_EQ(a.end, GraspState::Free);
  // Stopped within the target penetration (0.05 mm); the same hand without contact goes 4 mm in.
  EXPECT_GE(a.lowest, kPlateTop - 0.05 * kMm);
  EXPECT_LT(b.lowest, kPlateTop - 3 * kMm);
  EXPECT_GE(a.restingBottom, kPlateTop - 0.05 * kMm);  // put down on the plate, not in it
  EXPECT_NEAR(a.restingBottom, kPlateTop, 0.5 * kMm);
  // The wrist holds the hand up: the coupling's ~k_t x 4 mm against the weight of eq 30.
  const double weight = 0.1 * grasp::GraspParameters{}.gravity.norm();
  EXPECT_NEAR(b.holding.command.f_wrist.z(), -weight, 1e-9);
  EXPECT_GT(a.holding.command.f_wrist.z(), 5.0);
  EXPECT_GT(a.holding.command.m_wrist.norm(), b.holding.command.m_wrist.norm());
  // The grasp's own forces stay as they are.
  EXPECT_EQ(a.holding.command.f_index, b.holding.command.f_index);
  EXPECT_EQ(a.holding.command.f_grasp, b.holding.command.f_grasp);
  // The report: in contact with the plate, its faces named.
  const contact::ContactReport& c = a.holding.contact;
  EXPECT_EQ(c.part, 0);
  EXPECT_EQ(c.otherPart, 1);
  EXPECT_TRUE(c.clearanceExact);
  EXPECT_LT(c.clearance_m, 0.02 * kMm);
  EXPECT_GT(c.active, 0);
  EXPECT_GT(c.contactForce_N.z(), 5.0);
  EXPECT_GT(c.heldFace, 0);
  EXPECT_EQ(b.holding.contact.part, -1);
  // The contact scene knows where the block was put down.
  EXPECT_EQ(with.contact()->scene().body(0).pose.position, with.poses()[0].position);
  EXPECT_EQ(a.allocations, 0);
}

TEST(MultiFingerEngineContact, TheBlockStopsOnThePlateAndTheFingersFeelIt) {
  const grasp::ScenePtr scene = blockOverPlate(0.05);
  MultiFingerEngine with(scene, 2, {}, contactConfig()), without(scene, 2);
  const Outcome a = run(with, lowerOntoPlate(1.0));
  const Outcome b = run(without, lowerOntoPlate(1.0));
  ASSERT_TRUE(a.manipulated && b.manipulated);
  EXPECT_EQ(a.end, GraspState::Free);
  EXPECT_GE(a.lowest, kPlateTop - 0.05 * kMm);
  EXPECT_LT(b.lowest, kPlateTop - 3 * kMm);
  EXPECT_GE(a.restingBottom, kPlateTop - 0.05 * kMm);
  // The plate holds the block up: the fingers pushing it down feel that, not its weight.
  const auto upward = [](const EngineStep& s) { return s.command.f_index.z() + s.command.f_thumb.z(); };
  EXPECT_LT(upward(b.holding), 0.0);
  EXPECT_GT(upward(a.holding), upward(b.holding) + 0.3);
  EXPECT_EQ(a.holding.contact.part, 0);
  EXPECT_EQ(a.holding.contact.otherPart, 1);
  EXPECT_EQ(a.allocations, 0);
}

TEST(GraspEngineContact, APartWithoutAShellPassesThroughAndIsCounted) {
  std::vector<grasp::ScenePart> parts = test::blockOverPlateParts(0.1);
  parts[0].contact = nullptr;  // its shell failed, or its shape is still being read
  TwoFingerEngine engine(std::make_shared<const grasp::Scene>(std::move(parts)), {}, contactConfig());
  const Outcome r = run(engine, lowerOntoPlate(0.5));
  EXPECT_LT(r.lowest, kPlateTop - 3 * kMm);
  EXPECT_EQ(r.holding.contact.unmodelled, 1);
  EXPECT_EQ(r.holding.contact.part, -1);
}

}  // namespace
}  // namespace hg::servo
