#pragma once
// Scratch folders for the files tests write, under the system's temporary folder, removed
// with what they hold. ctest runs each test in a process of its own: folders left behind
// (recordings of a few MB each) piled up by the hundred.
#include <stdlib.h>

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <system_error>

namespace hg::test {

// A fresh folder of its own (mkdtemp: a name no one else has, mode 0700), removed when this goes.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "hg-test") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed for " + pattern);
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// One folder per `what` for the whole test process ("hg-<what>-XXXXXX"), made when first
// asked for and removed when the process exits: for what several tests share (a recording
// made once).
inline const std::filesystem::path& processTempDir(const std::string& what) {
  static std::map<std::string, TempDir> dirs;
  return dirs.try_emplace(what, "hg-" + what).first->second.path();
}

}  // namespace hg::test
