#pragma once
// A single-writer, multi-reader snapshot (a seqlock): the writer never waits, a reader
// retries while a write is in progress or if one overlapped its copy. The payload lives in
// relaxed atomic words, so a reader that races a write reads stale-or-torn words without a
// data race and throws them away on the sequence check (Boehm, "Can seqlocks get along
// with programming language memory models?", 2012).
//
// T is copied as bytes. It must be a plain aggregate of numbers and of Eigen fixed-size
// matrices (arrays of doubles with no pointers or invariants; Eigen does not declare them
// trivially copyable, hence the casts through void*).
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <thread>
#include <type_traits>

namespace hg::servo {

template <class T>
class SeqLock {
  static_assert(std::is_trivially_destructible_v<T>, "payload must be plain data");
  static constexpr std::size_t kWords = (sizeof(T) + sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t);

 public:
  // Writer only (one thread). Never blocks, never allocates.
  void write(const T& value) noexcept {
    const auto* bytes = static_cast<const unsigned char*>(static_cast<const void*>(&value));
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);  // odd: write in progress
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i) {
      std::uint64_t word = 0;
      const std::size_t offset = i * sizeof(word);
      std::memcpy(&word, bytes + offset, std::min(sizeof(word), sizeof(T) - offset));
      words_[i].store(word, std::memory_order_relaxed);
    }
    seq_.store(s + 2, std::memory_order_release);
  }

  // Any thread. False if a write overlapped (out is then unspecified) or nothing was
  // written yet.
  bool tryRead(T& out) const noexcept {
    const std::uint64_t s1 = seq_.load(std::memory_order_acquire);
    if (s1 == 0 || (s1 & 1)) return false;
    std::uint64_t buffer[kWords];
    for (std::size_t i = 0; i < kWords; ++i) buffer[i] = words_[i].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (seq_.load(std::memory_order_relaxed) != s1) return false;
    std::memcpy(static_cast<void*>(&out), static_cast<const void*>(buffer), sizeof(T));
    return true;
  }

  // Any thread: retries until a consistent copy is read; false only if nothing was ever
  // written.
  bool read(T& out) const noexcept {
    for (int attempt = 0;; ++attempt) {
      if (tryRead(out)) return true;
      if (seq_.load(std::memory_order_acquire) == 0) return false;
      if (attempt > 64) std::this_thread::yield();
    }
  }

  std::uint64_t writes() const noexcept { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  alignas(64) std::atomic<std::uint64_t> seq_{0};
  alignas(64) std::atomic<std::uint64_t> words_[kWords] = {};
};

}  // namespace hg::servo
