// The workbench loads its parts in the loader process: found in the build tree, the same part
// as a load in FreeCAD's process, a helper's crash one error naming the part, and a way back
// to FreeCAD's own process (and from it) when asked.
#include "part_loader.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "haptic_session.hpp"
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

// FreeCAD closing, or Cancel pressed, while a part loops in the loader: neither the part
// list's build nor a scene session waits out the loader's 60 s.
TEST_F(PartLoader, ACancelledBuildOrAnEndedSessionDoesNotWaitForTheLoader) {
  useLoader({"/bin/sh", "-c", "exec sleep 30"}, 60);
  auto start = std::chrono::steady_clock::now();
  {
    ModelBuild build({PartRequest{"Block", sampleBrep("block"), Placement{}, geometry::MassSpec::density(1000)}}, false);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    build.cancel();
    EXPECT_TRUE(build.wait(10));
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  start = std::chrono::steady_clock::now();
  {
    Session session;
    session.useHandInput(0.5);
    session.startScene({SceneRequest{"Block", "block", {-60, -60, -60}, {60, 60, 60}, Placement{},
                                     geometry::MassSpec::density(1000)}},
                       1000, false);
    session.provideShape(0, sampleBrep("block") + " ");  // a text no cache holds
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_FALSE(session.sceneStatus().finished) << "the stand-in loader is still 'loading'";
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
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
