#pragma once
// Where a build of HapticGrasp finds its data. A binary in the build tree (the CLI, the tests,
// the workbench's _hapticgrasp module) reads the source tree's resources/; an installed one
// reads the share folder of the prefix it was installed under (the Debian package: /usr),
// found from the binary's own place, so an unpacked package works wherever it is unpacked.
#include <filesystem>
#include <optional>

namespace hg {

// The executable or shared module that holds this code (the CLI, or _hapticgrasp.so inside
// FreeCAD's process), as the dynamic loader mapped it when this was first asked.
std::filesystem::path runningImage();

// The installation prefix of the running image: its nearest ancestor folder (at most six levels
// up: <prefix>/lib/python3/dist-packages/freecad/hapticgrasp/ is the deepest) that holds
// share/hapticgrasp. None for a binary in the build tree, or one whose data is missing.
std::optional<std::filesystem::path> installPrefix();

// $HAPTICGRASP_RESOURCES if set; the source tree's resources/ for a build-tree binary; else
// <installPrefix>/share/hapticgrasp; else /usr/share/hapticgrasp.
std::filesystem::path resourcesDir();

// The workbench's loader process (geometry/loader_process.hpp): $HAPTICGRASP_LOADER if set;
// the build tree's plugin/loader/hapticgrasp-loader for a build-tree binary; else
// <installPrefix>/lib/hapticgrasp/hapticgrasp-loader (Debian keeps a package's private
// programs under /usr/lib/<package>); else /usr/lib/hapticgrasp/hapticgrasp-loader. Whether
// it exists is the caller's to check.
std::filesystem::path loaderProgram();

}  // namespace hg
