#pragma once
// Optional: counts the heap allocations (malloc, calloc, realloc) made by each thread, by
// interposing those functions for the whole process. Include in EXACTLY ONE translation
// unit of an executable (a benchmark or test main), never in a library; then pass
// hg::servo::threadAllocations as ServoConfig::allocationCounter or to runServoBench.
//
// Under AddressSanitizer or ThreadSanitizer the sanitizer owns malloc: an interposer handing
// out glibc's blocks would have them freed by the sanitizer's free (ASan aborts on that). There
// the count comes from the sanitizer's own allocation hook instead, which sees every block its
// allocator hands out (malloc, calloc, realloc, operator new, aligned allocations), so the
// "the servo thread allocates nothing" checks keep their meaning in sanitized builds.
#include <cstddef>

#include "hapticgrasp/sanitized.hpp"

namespace hg::servo {
inline thread_local long mallocCounterCount = 0;
inline thread_local std::size_t mallocLargestRequest = 0;
inline long threadAllocations() { return mallocCounterCount; }
// The largest single request of this thread since the last reset: proves that what a file
// only claims (a declared size, a decompression bomb) never becomes an allocation.
inline std::size_t threadLargestAllocation() { return mallocLargestRequest; }
inline void resetThreadLargestAllocation() { mallocLargestRequest = 0; }
inline void countAllocation(std::size_t bytes) {
  ++mallocCounterCount;
  if (bytes > mallocLargestRequest) mallocLargestRequest = bytes;
}
}  // namespace hg::servo

#ifdef HG_SANITIZED
// sanitizer/allocator_interface.h: in the ASan and TSan runtimes, but GCC 12 ships no header.
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*, std::size_t),
                                                         void (*free_hook)(const volatile void*));

namespace hg::servo {
inline void countSanitizerAllocation(const volatile void*, std::size_t bytes) { countAllocation(bytes); }
inline void ignoreSanitizerFree(const volatile void*) {}  // the runtime wants both hooks
// Installed while the executable's statics are built, before main() and its threads. Internal
// linkage (this header goes into one translation unit), so the initializer always runs.
[[maybe_unused]] static const int mallocCounterHookInstalled =
    __sanitizer_install_malloc_and_free_hooks(countSanitizerAllocation, ignoreSanitizerFree);
}  // namespace hg::servo
#else
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
}

extern "C" {
void* malloc(std::size_t n) {
  hg::servo::countAllocation(n);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  hg::servo::countAllocation(n * size);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  hg::servo::countAllocation(n);
  return __libc_realloc(p, n);
}
}
#endif

