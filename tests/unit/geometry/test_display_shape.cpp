// A recorded shape made safe to show: checked as a part load checks it, meshed as FreeCAD's
// display will mesh it when asked, and handed over as text without triangles; a damaged one
// is refused with the reason.
#include "hapticgrasp/geometry/display_shape.hpp"

#include <BinTools.hxx>
#include <TopExp_Explorer.hxx>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

#include "geometry/part_answers.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "test_shapes.hpp"

namespace hg::geometry {
namespace {

using ::testing::StartsWith;

std::string binaryOf(const TopoDS_Shape& shape) {
  std::ostringstream out(std::ios::binary);
  BinTools::Write(shape, out);
  return out.str();
}

std::string binaryOfFile(const std::string& path) {
  return binaryOf(test::readShape(path));
}

std::string errorOf(std::string_view bytes, const DisplayCheck& check = {}) {
  try {
    displayableBrepText(bytes, LengthUnit::Millimetre, "tube", check);
  } catch (const GeometryError& e) {
    return e.what();
  }
  ADD_FAILURE() << "the shape was given out";
  return "";
}

TEST(DisplayShape, ACheckedShapeIsTheSameSolidAsTextAndItsDisplayMeshLeavesNoTrace) {
  for (const std::string name : {"block", "loft"}) {
    const std::string binary = binaryOfFile(std::string(HG_RESOURCES_DIR) + "/parts/" + name + ".brep");
    const std::string plain = displayableBrepText(binary, LengthUnit::Millimetre, name);
    DisplayCheck meshed;
    meshed.mesh = true;
    EXPECT_EQ(displayableBrepText(binary, LengthUnit::Millimetre, name, meshed), plain) << name;
    const PartModelPtr shown = PartModel::fromBrepText(plain, LengthUnit::Millimetre, name);
    test::expectSameAnswers(PartModel::fromBrepText(test::sample(name), LengthUnit::Millimetre, name), shown);
  }
}

TEST(DisplayShape, WhatCannotBeShownIsRefusedWithTheReason) {
  EXPECT_THAT(errorOf("not a shape"), StartsWith("is not a binary BREP"));
  EXPECT_EQ(errorOf(""), "is not a binary BREP");
  // The cylinder whose top edge goes 98 times round: BRepMesh meshed it for good.
  const std::string damaged =
      binaryOfFile(std::string(HG_TEST_DATA_DIR) + "/../fuzz/corpus/brep/timeout_edge_turns_98_times.brep");
  DisplayCheck meshed;
  meshed.mesh = true;
  EXPECT_EQ(errorOf(damaged, meshed),
            "is refused: the part's geometry is damaged: edge 1 goes 98.4 times round its curve (an edge goes round "
            "once at most)");
}

}  // namespace
}  // namespace hg::geometry
