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
  buffer_.t.insert(buffer_.t.end(), events.t.begin(), events.t.end());
  buffer_.x.insert(buffer_.x.end(), events.x.begin(), events.x.end());
  buffer_.y.insert(buffer_.y.end(), events.y.begin(), events.y.end());
  buffer_.p.insert(buffer_.p.end(), events.p.begin(), events.p.end());
}

bool EventBatcher::pop(EventBatch& out, bool flush) {
  out.clear();
  if (pending() == 0) return false;
  const Timestamp end_t = window_end(buffer_.t[head_]);
  std::size_t end = head_;
  while (end < buffer_.size() && end - head_ < max_events_ && buffer_.t[end] < end_t) ++end;
  const bool complete = end < buffer_.size() || end - head_ == max_events_;
  if (!complete && !flush) return false;
  const auto first = static_cast<std::ptrdiff_t>(head_), last = static_cast<std::ptrdiff_t>(end);
  out.t.assign(buffer_.t.begin() + first, buffer_.t.begin() + last);
  out.x.assign(buffer_.x.begin() + first, buffer_.x.begin() + last);
  out.y.assign(buffer_.y.begin() + first, buffer_.y.begin() + last);
  out.p.assign(buffer_.p.begin() + first, buffer_.p.begin() + last);
  head_ = end;
  return true;
}

}  // namespace evldt
