#pragma once
// Counts the heap allocations made by the calling thread, so that a test can prove a code
// path allocates nothing (as the servo thread must not). The interposer is the servo's
// own (malloc/calloc/realloc replaced for the whole process: OpenCASCADE allocates with
// malloc directly, not through operator new). Include in exactly one translation unit.
#include "hapticgrasp/servo/malloc_counter.hpp"

namespace hg::test {
inline long allocations() { return hg::servo::threadAllocations(); }
inline std::size_t largestAllocation() { return hg::servo::threadLargestAllocation(); }
inline void resetLargestAllocation() { hg::servo::resetThreadLargestAllocation(); }
}  // namespace hg::test
