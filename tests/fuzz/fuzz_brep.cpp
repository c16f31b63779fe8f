// BREP text, as the workbench hands a part over (FreeCAD's exportBrepToString) and as
// .brep files load: PartModel::fromBrepText, reading and every check. The one error it
// may throw is GeometryError; anything else, a crash or a sanitizer report is a bug.
#include "fuzz_support.hpp"
#include "hapticgrasp/geometry/part_model.hpp"

using namespace hg::geometry;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  hg::fuzz::quietOcct();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  PartLoadOptions options;
  options.parallel = false;  // one thread: libFuzzer's timeouts and stacks stay readable
  try {
    PartModel::fromBrepText(hg::fuzz::text(data, size), LengthUnit::Millimetre, "fuzz", options);
  } catch (const GeometryError&) {
  }
  return 0;
}
