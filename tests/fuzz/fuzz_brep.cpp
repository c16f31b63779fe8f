// BREP text, as the workbench hands a part over (FreeCAD's exportBrepToString) and as
// .brep files load: PartModel::fromBrepText, reading and every check. Built a second time
// as fuzz_brep_backend (HG_FUZZ_BACKEND): then also the back end a session builds after
// the load (makePenetration with the load's choice: a damaged part's mesh at 0.01 mm, the
// exact back end, a primitive's closed form). The one error either may throw is
// GeometryError; anything else, a crash or a sanitizer report is a bug.
#include "fuzz_support.hpp"
#include "hapticgrasp/geometry/backends.hpp"
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
    const PartModelPtr part = PartModel::fromBrepText(hg::fuzz::text(data, size), LengthUnit::Millimetre, "fuzz", options);
#ifdef HG_FUZZ_BACKEND
    makePenetration(part);
#endif
  } catch (const GeometryError&) {
  }
  return 0;
}
