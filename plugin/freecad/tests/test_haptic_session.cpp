// The session's snapshot carries what the task panel and the overlay show: the forces the
// operator feels, the grasping force, the hand in mm, and the servo's rate.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include "haptic_session.hpp"

namespace hg::freecad {
namespace {

std::string cylinderBrep() {
  std::ifstream in(std::string(HG_RESOURCES_DIR) + "/parts/cylinder.brep");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(HapticSession, SnapshotCarriesForcesHandAndRate) {
  Session session;
  // The cylinder (axis z, diameter 100 mm) stands where the document put it.
  session.addPart("Cylinder", cylinderBrep(), Placement{{0, 0, 200}, {0, 0, 0, 1}}, geometry::MassSpec::mass(2));
  session.useHandInput(0.5);
  session.start(1000, false);
  // Squeeze it across its diameter: index 5 mm inside at +x, thumb 5 mm inside at -x.
  const std::array<double, 3> index{45, 0, 200}, thumb{-45, 0, 200}, wrist{0, -100, 200};
  SessionSnapshot snap;
  for (int i = 0; i < 300; ++i) {
    session.setHand(index, thumb, wrist);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  snap = session.snapshot();
  session.stop();
  EXPECT_EQ(snap.state, "GRASP");
  EXPECT_GT(snap.graspForce_N, 1.0);
  // The index is pushed towards +x (apart from the thumb), the thumb towards -x.
  EXPECT_GT(snap.forces_N[0][0], 1.0);
  EXPECT_LT(snap.forces_N[1][0], -1.0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(snap.index_mm[k], index[k], 1e-9);
    EXPECT_NEAR(snap.thumb_mm[k], thumb[k], 1e-9);
    EXPECT_NEAR(snap.wrist_mm[k], wrist[k], 1e-9);
  }
  EXPECT_GT(snap.rate_hz, 100.0);  // ran; the figure itself is not asserted
  EXPECT_TRUE(std::isfinite(snap.jitter_us));
}

}  // namespace
}  // namespace hg::freecad
