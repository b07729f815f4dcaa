#include "evldt/transport/event_batcher.hpp"

#include <stdexcept>

namespace evldt {

EventBatcher::EventBatcher(Timestamp window_us, std::size_t max_events) : window_us_(window_us), max_events_(max_events) {
  if (window_us < 1 || max_events < 1) throw std::invalid_argument("batch window and size must be at least 1");
}

Timestamp EventBatcher::window_end(Timestamp t) const {
  const Timestamp index = t >= 0 ? t / window_us_ : -((-t - 1) / window_us_) - 1;  // floor division
  return (index + 1) * window_us_;
}

void EventBatcher::push(const EventBatch& events) {
  if (head_ > 0 && head_ * 2 >= buffer_.size()) {  // drop the consumed prefix before it dominates
    const auto erase = [&](auto& column) { column.erase(column.begin(), column.begin() + static_cast<std::ptrdiff_t>(head_)); };
    erase(buffer_.t);
    erase(buffer_.x);
    erase(buffer_.y);
    erase(buffer_.p);
    head_ = 0;
  }
  buffer_.append(events, 0, events.size());
}

bool EventBatcher::pop(EventBatch& out, bool flush) {
  out.clear();
  if (pending() == 0) return false;
  const Timestamp end_t = window_end(buffer_.t[head_]);
  std::size_t end = head_;
  while (end < buffer_.size() && end - head_ < max_events_ && buffer_.t[end] < end_t) ++end;
  const bool complete = end < buffer_.size() || end - head_ == max_events_;
  if (!complete && !flush) return false;
  out.append(buffer_, head_, end);  // out was cleared above
  head_ = end;
  return true;
}

}  // namespace evldt
