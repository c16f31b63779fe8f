#include "hapticgrasp/servo/tick_record.hpp"

#include <bit>

namespace hg::servo {

TickRecordRing::TickRecordRing(std::size_t capacity)
    : mask_(std::bit_ceil(capacity < 2 ? std::size_t{2} : capacity) - 1),
      items_(std::make_unique<TickRecord[]>(mask_ + 1)) {}

bool TickRecordRing::push(const TickRecord& record) noexcept {
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  if (head - tail_.load(std::memory_order_acquire) > mask_) {
    dropped_.fetch_add(1, std::memory_order_release);
    return false;
  }
  items_[head & mask_] = record;
  head_.store(head + 1, std::memory_order_release);
  return true;
}

bool TickRecordRing::pop(TickRecord& record) noexcept {
  const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
  if (tail == head_.load(std::memory_order_acquire)) return false;
  record = items_[tail & mask_];
  tail_.store(tail + 1, std::memory_order_release);
  return true;
}

}  // namespace hg::servo
