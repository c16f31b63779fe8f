#include "hapticgrasp/install_layout.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

namespace hg {
namespace {

namespace fs = std::filesystem;

// The installed case (a binary under <prefix>/bin finding <prefix>/share/hapticgrasp) is run
// for real by the package test (tests/packaging/check_package.py) on the unpacked .deb.

TEST(InstallLayout, TheRunningImageIsThisTestExecutable) {
  const fs::path image = runningImage();
  EXPECT_EQ(image, fs::canonical("/proc/self/exe"));
  EXPECT_EQ(image.filename(), "test_install_layout");
}

TEST(InstallLayout, ABinaryOfTheBuildTreeIsNotInstalledAndReadsTheSourceResources) {
  unsetenv("HAPTICGRASP_RESOURCES");
  EXPECT_FALSE(installPrefix().has_value());
  EXPECT_EQ(fs::canonical(resourcesDir()), fs::canonical(HG_RESOURCES_DIR));
  EXPECT_TRUE(fs::exists(resourcesDir() / "parts" / "parts.json"));
}

TEST(InstallLayout, TheEnvironmentOverridesEverything) {
  setenv("HAPTICGRASP_RESOURCES", "/somewhere/else", 1);
  EXPECT_EQ(resourcesDir(), fs::path("/somewhere/else"));
  unsetenv("HAPTICGRASP_RESOURCES");
  EXPECT_NE(resourcesDir(), fs::path("/somewhere/else"));
}

TEST(InstallLayout, TheLoaderProgramIsTheBuildTreesUnlessTheEnvironmentNamesOne) {
  unsetenv("HAPTICGRASP_LOADER");
  EXPECT_EQ(loaderProgram().filename(), "hapticgrasp-loader");
  EXPECT_EQ(loaderProgram().parent_path().filename(), "loader") << "the build tree's plugin/loader";
  setenv("HAPTICGRASP_LOADER", "/opt/loader", 1);
  EXPECT_EQ(loaderProgram(), fs::path("/opt/loader"));
  unsetenv("HAPTICGRASP_LOADER");
}

}  // namespace
}  // namespace hg
