#include "hapticgrasp/install_layout.hpp"

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <cstdlib>
#include <string_view>
#include <system_error>

namespace hg {
namespace {

namespace fs = std::filesystem;

bool isInside(const fs::path& path, const fs::path& folder) {
  const auto [end, _] = std::mismatch(folder.begin(), folder.end(), path.begin(), path.end());
  return end == folder.end();
}

fs::path canonicalOrEmpty(const fs::path& p) {
  std::error_code ec;
  fs::path c = fs::weakly_canonical(p, ec);
  return ec ? fs::path() : c;
}

// A binary of this build tree: its data is the source tree's, which it was built from.
bool inBuildTree(const fs::path& image) {
#if defined(HG_BUILD_DIR) && defined(HG_SOURCE_RESOURCES_DIR)
  std::error_code ec;
  return !image.empty() && isInside(image, canonicalOrEmpty(HG_BUILD_DIR)) &&
         fs::is_directory(HG_SOURCE_RESOURCES_DIR, ec);
#else
  (void)image;
  return false;
#endif
}

}  // namespace

fs::path runningImage() {
  // Once, at the first call: a binary replaced while it runs (rebuilt, or upgraded by apt
  // under an hour's soak) leaves /proc/self/exe pointing at a deleted file, and the data
  // would be looked for elsewhere from then on ("no sample part catalogue", mid-soak).
  static const fs::path image = [] {
    // dladdr1's link map names the shared object; the main program's has an empty name, and
    // its path is /proc/self/exe (dladdr would give argv[0], which may be a bare name).
    Dl_info info{};
    link_map* map = nullptr;
    if (dladdr1(reinterpret_cast<void*>(&runningImage), &info, reinterpret_cast<void**>(&map),
                RTLD_DL_LINKMAP) != 0 &&
        map && map->l_name && map->l_name[0] != '\0')
      return canonicalOrEmpty(map->l_name);
    return canonicalOrEmpty("/proc/self/exe");
  }();
  return image;
}

std::optional<fs::path> installPrefix() {
  const fs::path image = runningImage();
  if (image.empty() || inBuildTree(image)) return std::nullopt;
  fs::path dir = image.parent_path();
  for (int up = 0; up < 7 && !dir.empty(); ++up, dir = dir.parent_path()) {
    std::error_code ec;
    if (fs::is_directory(dir / "share" / "hapticgrasp", ec)) return dir;
    if (dir == dir.root_path()) break;
  }
  return std::nullopt;
}

fs::path resourcesDir() {
  if (const char* env = std::getenv("HAPTICGRASP_RESOURCES"); env && *env) return env;
#ifdef HG_SOURCE_RESOURCES_DIR
  if (inBuildTree(runningImage())) return HG_SOURCE_RESOURCES_DIR;
#endif
  if (const auto prefix = installPrefix()) return *prefix / "share" / "hapticgrasp";
  return "/usr/share/hapticgrasp";
}

fs::path loaderProgram() {
  if (const char* env = std::getenv("HAPTICGRASP_LOADER"); env && *env) return env;
#ifdef HG_LOADER_BUILD_PATH
  if (inBuildTree(runningImage())) return HG_LOADER_BUILD_PATH;
#endif
  const fs::path relative = fs::path("lib") / "hapticgrasp" / "hapticgrasp-loader";
  if (const auto prefix = installPrefix()) return *prefix / relative;
  return fs::path("/usr") / relative;
}

}  // namespace hg
