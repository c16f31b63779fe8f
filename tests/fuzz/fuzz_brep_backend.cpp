// A BREP part's back end, as a session builds it after the load (the scene's build thread,
// `parts info`): PartModel::fromBrepText, then makePenetration with the back end the load
// chose (a damaged part's mesh at 0.01 mm, the exact back end's patches, a primitive's
// closed form). Seeds: corpus/brep. The one error it may throw is GeometryError; anything
// else, a crash or a sanitizer report is a bug.
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
    makePenetration(PartModel::fromBrepText(hg::fuzz::text(data, size), LengthUnit::Millimetre, "fuzz", options));
  } catch (const GeometryError&) {
  }
  return 0;
}
