// The workbench loads its parts in the loader process: found in the build tree, the same part
// as a load in FreeCAD's process, a helper's crash one error naming the part, and a way back
// to FreeCAD's own process (and from it) when asked.
#include "part_loader.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::freecad {
namespace {

std::string sampleBrep(const std::string& name) {
  std::ifstream in(std::string(HG_RESOURCES_DIR) + "/parts/" + name + ".brep");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class PartLoader : public ::testing::Test {
 protected:
  void TearDown() override { useLoader({}, 60); }  // the next test finds the default again
};

TEST_F(PartLoader, PartsLoadInTheBuildTreesLoaderProcess) {
  useLoader({}, 60);
  LoaderStatus s = loaderStatus();
  ASSERT_TRUE(s.isolated) << s.why;
  EXPECT_NE(s.program.find("plugin/loader/hapticgrasp-loader"), std::string::npos) << s.program;
  EXPECT_EQ(s.timeLimit_s, 60);
  const auto block = loadPartText(sampleBrep("block"), "Block", {});
  EXPECT_EQ(block->faces().Extent(), 58);
  EXPECT_EQ(block->name(), "Block");
  EXPECT_NEAR(block->metresPerUnit(), 1e-3, 1e-18) << "FreeCAD's millimetres";
  EXPECT_EQ(loaderStatus().started, 1u);
  geometry::ModelCache memoryOnly({});
  const auto cylinder = memoryOnly.load(sampleBrep("cylinder"), geometry::LengthUnit::Millimetre, "C", {}, nullptr,
                                        cacheBuild());
  EXPECT_EQ(cylinder->faces().Extent(), 3);
  EXPECT_EQ(loaderStatus().started, 1u) << "the cache's loads go to the same helper";
}

TEST_F(PartLoader, AHelperThatCrashesCostsThePartNotTheWorkbench) {
  useLoader({"/bin/sh", "-c", "head -c 10 >/dev/null; kill -SEGV $$"}, 5);
  try {
    loadPartText(sampleBrep("block"), "Block", {});
    ADD_FAILURE() << "the load answered";
  } catch (const geometry::GeometryError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("loading Block in the loader process crashed (SIGSEGV", 0), 0u) << e.what();
  }
  geometry::ModelCache memoryOnly({});
  EXPECT_THROW(memoryOnly.load(sampleBrep("cylinder"), geometry::LengthUnit::Millimetre, "C", {}, nullptr, cacheBuild()),
               geometry::GeometryError);
  EXPECT_EQ(loaderStatus().started, 2u) << "a new helper for each part after a crash";
}

TEST_F(PartLoader, WithoutALoaderPartsLoadInThisProcess) {
  useNoLoader("turned off by the test");
  const LoaderStatus s = loaderStatus();
  EXPECT_FALSE(s.isolated);
  EXPECT_EQ(s.why, "turned off by the test");
  EXPECT_FALSE(cacheBuild());
  EXPECT_EQ(loadPartText(sampleBrep("cylinder"), "C", {})->faces().Extent(), 3);
  setenv("HAPTICGRASP_LOADER", "/nonexistent/loader", 1);
  useLoader({}, 60);
  const LoaderStatus missing = loaderStatus();
  unsetenv("HAPTICGRASP_LOADER");
  EXPECT_FALSE(missing.isolated);
  EXPECT_EQ(missing.why, "no loader program at /nonexistent/loader");
  EXPECT_EQ(loadPartText(sampleBrep("cylinder"), "C", {})->faces().Extent(), 3);
  EXPECT_THROW(useLoader({"x"}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace hg::freecad
