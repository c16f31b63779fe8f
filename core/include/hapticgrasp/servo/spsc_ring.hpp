#pragma once
// A bounded single-producer single-consumer ring of small trivially copyable items
// (commands from the GUI thread to the servo thread). Lock-free, allocation-free after
// construction: push() from one thread only, pop() from one other thread only.
#include <array>
#include <atomic>
#include <cstddef>
#include <type_traits>

namespace hg::servo {

template <class T, std::size_t N>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "ring items are copied by value");
  static_assert(N >= 2 && (N & (N - 1)) == 0, "capacity must be a power of two");

 public:
  // Producer only. False when full (the item is dropped; the caller decides).
  bool push(const T& item) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == N) return false;
    items_[head & (N - 1)] = item;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  // Consumer only. False when empty.
  bool pop(T& item) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    item = items_[tail & (N - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }
  static constexpr std::size_t capacity() { return N; }

 private:
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::array<T, N> items_{};
};

}  // namespace hg::servo
