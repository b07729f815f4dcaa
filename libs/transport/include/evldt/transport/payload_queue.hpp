#pragma once
// A bounded queue of message payloads from the thread that handles LCM to the one that works on
// them (one of each). The handler copies a payload in and returns at once, so LCM's own queue stays
// near empty: LCM 1.3 keeps a received message in a ring that cannot be reused past a small message
// still queued, and grows by fresh allocations while one waits (measured at 1280x720 x1: the ring
// grew ten times to 12 MB in the first half second, its reading thread spent half its time faulting
// the new pages in, and the socket overflowed). The slots are allocated and touched once, at
// construction: copying in costs a memcpy, never an allocation, unless a payload is larger than
// every one before it.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

namespace evldt {

class PayloadQueue {
 public:
  /// A queued payload and when it was received (wall clock, us).
  struct Queued {
    std::span<const std::uint8_t> bytes;
    std::int64_t received_utime = 0;
  };

  /// `slots` payloads at most, each slot touched for `slot_bytes` from the start. Throws
  /// std::invalid_argument for no slots.
  PayloadQueue(std::size_t slots, std::size_t slot_bytes);

  /// Copies `payload`, received at `received_utime`, in. While every slot is full, waits for one
  /// (checking `stop` every 100 ms): false if stopped first, the payload then not queued.
  bool push(std::span<const std::uint8_t> payload, std::int64_t received_utime, const std::atomic<bool>& stop);
  /// The oldest payload, waiting up to `timeout` for one; it stays queued (and valid) until pop().
  [[nodiscard]] std::optional<Queued> front(std::chrono::milliseconds timeout);
  /// Frees the slot of the payload front() returned.
  void pop();

  /// The most payloads queued at once so far.
  [[nodiscard]] std::size_t high_water() const;

 private:
  struct Slot {
    std::vector<std::uint8_t> bytes;  ///< never shrinks: its size is the slot's capacity
    std::size_t size = 0;
    std::int64_t received_utime = 0;
  };
  std::vector<Slot> slots_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::size_t head_ = 0;   ///< the next slot to read (guarded by mutex_)
  std::size_t count_ = 0;  ///< payloads queued (guarded by mutex_)
  std::size_t high_water_ = 0;
};

}  // namespace evldt
