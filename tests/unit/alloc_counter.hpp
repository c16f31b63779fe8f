#pragma once
// Counts the heap allocations made by the calling thread, so that a test can prove a code
// path allocates nothing (as the servo thread must not). OpenCASCADE allocates with malloc directly (Standard::Allocate), not
// through operator new, so malloc itself is interposed: the executable's definition wins
// over libc's for every shared library too. Include in exactly one translation unit.
#include <cstddef>

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
}

namespace hg::test {
inline thread_local long allocationCount = 0;
inline long allocations() { return allocationCount; }
}  // namespace hg::test

extern "C" {
void* malloc(std::size_t n) {
  ++hg::test::allocationCount;
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  ++hg::test::allocationCount;
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  ++hg::test::allocationCount;
  return __libc_realloc(p, n);
}
}
