#include "evldt/transport/event_batcher.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace evldt {
namespace {
// Consumed segments kept for reuse: the camera cycles through three (one being read, one being
// batched, the one whose last window is still open).
constexpr std::size_t kMaxSpares = 2;
}  // namespace

EventBatcher::EventBatcher(Timestamp window_us, std::size_t max_events)
    : window_us_(window_us), max_events_(max_events) {
  if (window_us < 1 || max_events < 1) throw std::invalid_argument("batch window and size must be at least 1");
}

Timestamp EventBatcher::window_end(Timestamp t) const {
  const Timestamp index = t >= 0 ? t / window_us_ : -((-t - 1) / window_us_) - 1;  // floor division
  return (index + 1) * window_us_;
}

EventBatch EventBatcher::take_spare() {
  if (spares_.empty()) return {};
  EventBatch spare = std::move(spares_.back());
  spares_.pop_back();
  spare.clear();
  return spare;
}

void EventBatcher::push(const EventBatch& events) {
  if (events.empty()) return;
  EventBatch segment = take_spare();
  segment.append(events, 0, events.size());
  pending_ += segment.size();
  segments_.push_back(std::move(segment));
}

void EventBatcher::push(EventBatch&& events) {
  if (events.empty()) return;
  pending_ += events.size();
  segments_.push_back(std::exchange(events, take_spare()));
}

bool EventBatcher::pop(EventBatch& out, bool flush) {
  out.clear();
  if (pending_ == 0) return false;
  // The batch runs from head_ of the first segment to `end` of segment `last`: events before the
  // end of the window, at most max_events of them. It is complete if an event follows it.
  const Timestamp end_t = window_end(segments_.front().t[head_]);
  std::size_t count = 0, last = 0, begin = head_, end = head_;
  bool complete = false;
  for (;;) {
    const EventBatch& segment = segments_[last];
    const Timestamp* t = segment.t.data();
    const std::size_t limit = std::min(segment.size(), begin + (max_events_ - count));
    end = begin;
    while (end < limit && t[end] < end_t) ++end;
    count += end - begin;
    if (end < segment.size() || count == max_events_) {
      complete = true;  // an event of a later window, or of the next batch, follows
      break;
    }
    if (last + 1 == segments_.size()) break;  // the end of the stream so far
    ++last;
    begin = end = 0;
  }
  if (!complete && !flush) return false;

  // Copy the batch out (out was cleared above), then drop the segments it used up.
  out.reserve(count);
  for (std::size_t s = 0; s <= last; ++s) {
    const EventBatch& segment = segments_[s];
    out.append(segment, s == 0 ? head_ : 0, s == last ? end : segment.size());
  }
  pending_ -= count;
  head_ = end;
  if (head_ == segments_[last].size()) {
    ++last;
    head_ = 0;
  }
  for (std::size_t s = 0; s < last; ++s) {
    if (spares_.size() < kMaxSpares) spares_.push_back(std::move(segments_.front()));
    segments_.pop_front();
  }
  return true;
}

}  // namespace evldt
