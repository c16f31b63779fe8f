// A model swap as a recording's message: the part's description and its binary BREP come
// back as they went in; bytes that are not a swap get a clear error.
#include <gtest/gtest.h>

#include "hapticgrasp/servo/servo_bench.hpp"
#include "hapticgrasp/session/model_swap_message.hpp"

namespace hg::session {
namespace {

TEST(ModelSwapMessage, RoundTripsThePartAndItsShape) {
  const grasp::ScenePart cylinder = servo::benchScene()->part(0);
  ModelSwap swap{41, 3, describePart(cylinder, "Cylinder001")};
  ASSERT_FALSE(swap.model.brep.empty());
  std::string bytes;
  encodeModelSwap(swap, bytes);
  const ModelSwap back = decodeModelSwap(bytes);
  EXPECT_EQ(back.publication, 41u);
  EXPECT_EQ(back.part, 3);
  EXPECT_EQ(back.model.name, "Cylinder001");
  EXPECT_EQ(back.model.brep, swap.model.brep);
  EXPECT_EQ(back.model.contentHash, swap.model.contentHash);
  EXPECT_EQ(back.model.faces, cylinder.model->faces().Extent());
  EXPECT_EQ(back.model.mass.mass_kg, cylinder.mass.mass_kg);
  EXPECT_FALSE(back.model.coarse);
}

TEST(ModelSwapMessage, AStandInTravelsWithoutAShape) {
  const grasp::ScenePart cylinder = servo::benchScene()->part(0);
  const grasp::ScenePart box = grasp::makeCoarseScenePart(cylinder.bounds, geometry::MassSpec::mass(2), cylinder.initialPose);
  std::string bytes;
  encodeModelSwap({0, 0, describePart(box, "box")}, bytes);
  const ModelSwap back = decodeModelSwap(bytes);
  EXPECT_TRUE(back.model.coarse);
  EXPECT_TRUE(back.model.brep.empty());
  EXPECT_EQ(back.model.faces, 0);
  EXPECT_EQ(back.model.bounds.max, cylinder.bounds.max);
}

TEST(ModelSwapMessage, BytesThatAreNotASwapGetAClearError) {
  EXPECT_THROW(decodeModelSwap("\xff\xff\xff"), SessionError);
  std::string bytes;
  encodeModelSwap({0, 0, describePart(servo::benchScene()->part(0), "c")}, bytes);
  try {
    decodeModelSwap(bytes.substr(0, bytes.size() / 2));
    FAIL() << "half a message decoded";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("model swap"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hg::session
