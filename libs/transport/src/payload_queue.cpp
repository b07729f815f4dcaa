#include "evldt/transport/payload_queue.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace evldt {

PayloadQueue::PayloadQueue(std::size_t slots, std::size_t slot_bytes) : slots_(slots) {
  if (slots == 0) throw std::invalid_argument("a payload queue needs at least one slot");
  for (Slot& slot : slots_) slot.bytes.resize(slot_bytes);  // zero-filled: every page touched now
}

bool PayloadQueue::push(std::span<const std::uint8_t> payload, std::int64_t received_utime,
                        const std::atomic<bool>& stop) {
  std::size_t index = 0;
  {
    std::unique_lock lock(mutex_);
    while (count_ == slots_.size()) {
      if (stop.load()) return false;
      not_full_.wait_for(lock, std::chrono::milliseconds(100));
    }
    index = (head_ + count_) % slots_.size();
  }
  // The slot is the producer's until counted in below: the consumer reads only counted slots.
  Slot& slot = slots_[index];
  if (slot.bytes.size() < payload.size()) slot.bytes.resize(payload.size());
  if (!payload.empty()) std::memcpy(slot.bytes.data(), payload.data(), payload.size());
  slot.size = payload.size();
  slot.received_utime = received_utime;
  {
    std::lock_guard lock(mutex_);
    ++count_;
    high_water_ = std::max(high_water_, count_);
  }
  not_empty_.notify_one();
  return true;
}

std::optional<PayloadQueue::Queued> PayloadQueue::front(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  if (!not_empty_.wait_for(lock, timeout, [this] { return count_ > 0; })) return std::nullopt;
  const Slot& slot = slots_[head_];
  return Queued{std::span<const std::uint8_t>(slot.bytes.data(), slot.size), slot.received_utime};
}

void PayloadQueue::pop() {
  {
    std::lock_guard lock(mutex_);
    if (count_ == 0) return;
    head_ = (head_ + 1) % slots_.size();
    --count_;
  }
  not_full_.notify_one();
}

std::size_t PayloadQueue::high_water() const {
  std::lock_guard lock(mutex_);
  return high_water_;
}

}  // namespace evldt
