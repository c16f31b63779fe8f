#pragma once
// What the fuzz targets share: the input as text, a file holding it for the loaders that
// only read paths, and a quiet OpenCASCADE (its readers print per file; a target that
// prints per input buries libFuzzer's own report and slows the run).
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <unistd.h>

#include "hapticgrasp/geometry/occt_faults.hpp"

namespace hg::fuzz {

inline std::string_view text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// OCCT's faults become errors as in the command line (occt_faults.hpp), and its messages
// go nowhere.
inline void quietOcct() {
  geometry::catchOcctFaults();
  Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
}

// One file per process, rewritten per input: loaders that take a path read it. In the
// temporary folder, named by the process so parallel runs (-jobs) do not share one.
class InputFile {
 public:
  explicit InputFile(const std::string& extension)
      : path_(std::filesystem::temp_directory_path() /
              ("hg_fuzz_" + std::to_string(::getpid()) + extension)) {}
  ~InputFile() { std::remove(path_.c_str()); }
  const std::filesystem::path& write(const std::uint8_t* data, std::size_t size) {
    std::ofstream(path_, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                                   static_cast<std::streamsize>(size));
    return path_;
  }

 private:
  std::filesystem::path path_;
};

}  // namespace hg::fuzz
