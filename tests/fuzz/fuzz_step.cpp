// STEP files: PartModel::fromFile on a .step, OCCT's reader and transfer, then the same
// checks as BREP. Documented errors: GeometryError only. The reader only takes a path,
// so each input is written to a file first.
#include "fuzz_support.hpp"
#include "hapticgrasp/geometry/part_model.hpp"

using namespace hg::geometry;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  hg::fuzz::quietOcct();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static hg::fuzz::InputFile file(".step");
  PartLoadOptions options;
  options.parallel = false;
  try {
    PartModel::fromFile(file.write(data, size), LengthUnit::Millimetre, options);
  } catch (const GeometryError&) {
  }
  return 0;
}
