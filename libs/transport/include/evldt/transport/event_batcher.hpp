#pragma once
// Cuts a time-ordered event stream into batches for the wire: one batch per time window of
// window_us (aligned to multiples of it), split further so no batch exceeds max_events (one UDP
// datagram holds about 7000 events; larger messages are fragmented by LCM).

#include <cstddef>
#include <deque>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt {

class EventBatcher {
 public:
  /// Throws std::invalid_argument unless window_us >= 1 and max_events >= 1.
  EventBatcher(Timestamp window_us, std::size_t max_events);

  /// Appends events (in time order) to the stream.
  void push(const EventBatch& events);
  /// The same without copying them: the batcher keeps the columns of `events` and leaves it empty
  /// (holding the storage of a batch already consumed, if there is one, to be filled again).
  void push(EventBatch&& events);
  /// Moves the next complete batch into `out` (cleared first). A window is complete once an event
  /// of a later window has arrived or it holds max_events; `flush` also gives the incomplete tail.
  bool pop(EventBatch& out, bool flush = false);
  /// Events pushed but not popped.
  [[nodiscard]] std::size_t pending() const { return pending_; }

 private:
  [[nodiscard]] Timestamp window_end(Timestamp t) const;
  /// An empty batch, with the storage of a consumed one if there is one.
  EventBatch take_spare();

  Timestamp window_us_;
  std::size_t max_events_;
  // The stream in the batches it was pushed as (none empty), the first consumed up to head_.
  std::deque<EventBatch> segments_;
  std::size_t head_ = 0;
  std::size_t pending_ = 0;
  std::vector<EventBatch> spares_;  // consumed segments, kept for their storage
};

}  // namespace evldt
