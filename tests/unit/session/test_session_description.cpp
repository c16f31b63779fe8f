// The session description a recording carries: every parameter round-trips through its
// JSON to the bit (replay depends on it), parts carry their exact shapes, and a damaged
// description says which field is wrong.
#include <gtest/gtest.h>

#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BinTools.hxx>
#include <GProp_GProps.hxx>
#include <TopExp_Explorer.hxx>

#include <cstring>
#include <sstream>

#include "hapticgrasp/servo/servo_bench.hpp"
#include "hapticgrasp/session/session_description.hpp"
#include "test_shapes.hpp"

namespace hg::session {
namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

SessionDescription sample() {
  SessionDescription d;
  d.document = "Review.FCStd";
  d.software = "hapticgrasp test";
  d.build = softwareBuild();
  d.created_utc = utcNow();
  d.method = "multi-finger";
  d.fingertips = 3;
  d.rate_hz = 4000;
  d.watchdogRamp_s = 0.1 / 3;  // not a short decimal: the JSON must keep every bit
  d.passivityController = true;
  d.device.name = "scripted hand";
  d.device.maxForce_N = 1.0 / 7;
  d.twoFinger.K_c = 130.0000000001;
  d.twoFinger.rotationalSpring = grasp::RotationalSpring::PaperRpy;
  d.multiFinger.grasp.friction = 0.3;
  d.multiFinger.grasp.distribution.gamma2 = 1e-300;
  d.contact = true;
  d.contactConfig.constrain = false;
  d.contactModel.maxPoints = 700;
  d.contactModel.edgeDensity = 1.0 / 3;
  d.contactConfig.coupling.stiffness.translational_N_m = 1234.5678901;
  d.contactConfig.coupling.maxRotationalPassivityDamping_Nms_rad = 0.1 / 7;
  d.contactConfig.query.queryBudget = 17;
  d.parts = describeParts(*servo::benchScene());
  return d;
}

TEST(SessionDescription, RoundTripsEveryParameterToTheBit) {
  const SessionDescription d = sample();
  const SessionDescription e = sessionFromJson(toJson(d));
  EXPECT_EQ(e.document, d.document);
  EXPECT_EQ(e.method, "multi-finger");
  EXPECT_EQ(e.fingertips, 3);
  EXPECT_TRUE(sameBits(e.watchdogRamp_s, d.watchdogRamp_s));
  EXPECT_TRUE(e.passivityController);
  EXPECT_TRUE(sameBits(e.device.maxForce_N, d.device.maxForce_N));
  EXPECT_TRUE(sameBits(e.twoFinger.K_c, d.twoFinger.K_c));
  EXPECT_EQ(e.twoFinger.rotationalSpring, grasp::RotationalSpring::PaperRpy);
  EXPECT_TRUE(sameBits(e.multiFinger.grasp.distribution.gamma2, 1e-300));
  EXPECT_TRUE(e.contact);
  EXPECT_FALSE(e.contactConfig.constrain);
  EXPECT_EQ(e.contactModel.maxPoints, 700);
  EXPECT_TRUE(sameBits(e.contactModel.edgeDensity, 1.0 / 3));
  EXPECT_TRUE(sameBits(e.contactConfig.coupling.stiffness.translational_N_m, 1234.5678901));
  EXPECT_TRUE(sameBits(e.contactConfig.coupling.maxRotationalPassivityDamping_Nms_rad, 0.1 / 7));
  EXPECT_EQ(e.contactConfig.query.queryBudget, 17);
  ASSERT_EQ(e.parts.size(), 1u);
  const RecordedPart &p = d.parts[0], &q = e.parts[0];
  EXPECT_EQ(q.name, p.name);
  EXPECT_EQ(q.backend, p.backend);
  EXPECT_EQ(q.attachment, p.attachment);
  EXPECT_TRUE(q.brep.empty()) << "the shape travels as an attachment, not in the JSON";
  EXPECT_TRUE(sameBits(q.mass.mass_kg, p.mass.mass_kg));
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(sameBits(q.mass.centre_m[i], p.mass.centre_m[i]));
    EXPECT_TRUE(sameBits(q.initialPose.position[i], p.initialPose.position[i]));
    for (int j = 0; j < 3; ++j) {
      EXPECT_TRUE(sameBits(q.initialPose.rotation(i, j), p.initialPose.rotation(i, j)));
      EXPECT_TRUE(sameBits(q.mass.inertia_kgm2(i, j), p.mass.inertia_kgm2(i, j)));
    }
  }
}

TEST(SessionDescription, PartsCarryTheirExactShapeAndAStableHash) {
  const auto parts = describeParts(*servo::benchScene());
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_EQ(parts[0].name, "cylinder");
  EXPECT_EQ(parts[0].backend, "analytic");
  EXPECT_FALSE(parts[0].brep.empty());
  EXPECT_EQ(parts[0].contentHash, contentHash(parts[0].brep));
  EXPECT_EQ(parts[0].attachment, "parts/" + parts[0].contentHash + ".brep");
  EXPECT_EQ(describeParts(*servo::benchScene())[0].contentHash, parts[0].contentHash);  // the same shape, the same hash
  EXPECT_NE(contentHash("a"), contentHash("b"));
}

// FreeCAD reads the text; the text is the same solid (faces, volume to 1e-9).
TEST(SessionDescription, ARecordedShapeReadsBackAsTextBrep) {
  const RecordedPart part = describeParts(*servo::benchScene())[0];
  std::istringstream in(brepAsText(part));
  TopoDS_Shape text;
  BRep_Builder builder;
  BRepTools::Read(text, in, builder);
  ASSERT_FALSE(text.IsNull());
  TopoDS_Shape binary;
  std::istringstream bin(part.brep, std::ios::binary);
  BinTools::Read(binary, bin);
  int faces = 0;
  for (TopExp_Explorer e(text, TopAbs_FACE); e.More(); e.Next()) ++faces;
  EXPECT_EQ(faces, part.faces);
  GProp_GProps a, b;
  BRepGProp::VolumeProperties(text, a);
  BRepGProp::VolumeProperties(binary, b);
  EXPECT_GT(b.Mass(), 0.0);
  EXPECT_NEAR(a.Mass(), b.Mass(), 1e-9 * b.Mass());
  RecordedPart broken = part;
  for (const std::string bytes : {"not a shape", ""}) {
    broken.brep = bytes;
    EXPECT_THROW(brepAsText(broken), SessionError);
  }
}

// A recording may come from anyone: a shape the part load refuses never reaches FreeCAD
// (the cylinder whose top edge goes 98 times round, which BRepMesh meshed for good).
TEST(SessionDescription, ARecordedShapeThePartLoadRefusesIsNotGivenOut) {
  const TopoDS_Shape damaged =
      test::readShape(std::string(HG_TEST_DATA_DIR) + "/../fuzz/corpus/brep/timeout_edge_turns_98_times.brep");
  std::ostringstream binary(std::ios::binary);
  BinTools::Write(damaged, binary);
  RecordedPart part = describeParts(*servo::benchScene())[0];
  part.name = "tube";
  part.brep = binary.str();
  try {
    brepAsText(part);
    ADD_FAILURE() << "a damaged shape was given out";
  } catch (const SessionError& e) {
    EXPECT_EQ(std::string(e.what()),
              "part 'tube': its recorded shape is refused: the part's geometry is damaged: edge 1 goes 98.4 times "
              "round its curve (an edge goes round once at most)");
  }
}

TEST(SessionDescription, ADamagedDescriptionNamesWhatIsWrong) {
  std::string json = toJson(sample());
  EXPECT_THROW(sessionFromJson("not json"), SessionError);
  EXPECT_THROW(sessionFromJson("[1, 2]"), SessionError);
  const auto at = json.find("\"rate_hz\"");
  ASSERT_NE(at, std::string::npos);
  json.replace(at, 9, "\"rate_HZ\"");
  try {
    sessionFromJson(json);
    FAIL() << "a missing field was accepted";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("rate_hz"), std::string::npos) << e.what();
  }
}

// A recording from someone else is untrusted: a contact count that would size a buffer
// beyond reason is refused by name, before anything is built from it.
TEST(SessionDescription, AContactCountBeyondItsRangeIsRefused) {
  std::string json = toJson(sample());
  const auto at = json.find("\"query_budget\":17");
  ASSERT_NE(at, std::string::npos);
  std::string huge = json;
  const auto points = huge.find("\"max_points\":700");
  ASSERT_NE(points, std::string::npos);
  huge.replace(points, 16, "\"max_points\":1e12");
  try {
    sessionFromJson(huge);
    FAIL() << "a shell of 1e12 points was accepted";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("max_points"), std::string::npos) << e.what();
  }
  const auto constrain = json.find("\"constrain\":false");
  ASSERT_NE(constrain, std::string::npos);
  json.replace(constrain, 19, "\"constrain\":\"no\"");
  EXPECT_THROW(sessionFromJson(json), SessionError);
}

}  // namespace
}  // namespace hg::session
