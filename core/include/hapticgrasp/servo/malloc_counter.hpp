#pragma once
// Optional: counts the heap allocations (malloc, calloc, realloc) made by each thread, by
// interposing those functions for the whole process. Include in EXACTLY ONE translation
// unit of an executable (a benchmark or test main), never in a library; then pass
// hg::servo::threadAllocations as ServoConfig::allocationCounter or to runServoBench.
#include <cstddef>

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
}

namespace hg::servo {
inline thread_local long mallocCounterCount = 0;
inline long threadAllocations() { return mallocCounterCount; }
}  // namespace hg::servo

extern "C" {
void* malloc(std::size_t n) {
  ++hg::servo::mallocCounterCount;
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  ++hg::servo::mallocCounterCount;
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  ++hg::servo::mallocCounterCount;
  return __libc_realloc(p, n);
}
}
