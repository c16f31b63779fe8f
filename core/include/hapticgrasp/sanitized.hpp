#pragma once
// HG_SANITIZED: defined when this translation unit is built under AddressSanitizer or
// ThreadSanitizer (make sanitize), for the few places a sanitizer changes what can be asked
// of the process: its shadow memory takes terabytes of address space, and it runs several
// times slower than real time. GCC names them __SANITIZE_*__, clang __has_feature.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define HG_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define HG_SANITIZED 1
#endif
#endif
