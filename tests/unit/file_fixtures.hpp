#pragma once
// Whole files in and out, for the tests that read parts, recordings and texts from disk.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

namespace hg::test {

// The file's bytes; empty if it cannot be read.
inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void writeFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace hg::test
