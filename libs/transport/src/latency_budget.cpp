#include "evldt/transport/latency_budget.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace evldt {

LatencyBudget::LatencyBudget(double max_latency_ms, std::int64_t window_us, OverloadPolicy policy)
    : budget_us_(std::llround(max_latency_ms * 1e3)), window_us_(window_us), policy_(policy) {
  if (!(max_latency_ms >= 0 && max_latency_ms <= 3.6e6) || window_us <= 0) {
    throw std::invalid_argument("the latency budget must be in 0 .. 3600000 ms and its window positive");
  }
}

int LatencyBudget::stride(std::int64_t publish_utime, std::int64_t now_utime) {
  const std::int64_t delay = now_utime - publish_utime;
  if (!started_ || now_utime - window_start_ >= window_us_ || now_utime < window_start_) {
    // A new window (or our clock stepped back): the one that ended becomes the previous.
    previous_min_ = started_ ? current_min_ : delay;
    current_min_ = delay;
    window_start_ = now_utime;
    started_ = true;
  }
  current_min_ = std::min(current_min_, delay);
  last_queueing_us_ = delay - std::min(current_min_, previous_min_);
  if (budget_us_ <= 0 || (exempt_ && publish_utime <= exempt_until_publish_)) return 1;
  if (last_queueing_us_ <= budget_us_) return 1;
  if (policy_ == OverloadPolicy::Shed || last_queueing_us_ > 2 * budget_us_) return 0;
  // Thinned from the budget on, not below it: thinning earlier (from a quarter or half of it) stretched
  // the rounds and thinned batches storage would have caught up with (docs/realtime.md).
  return last_queueing_us_ <= budget_us_ * 3 / 2 ? 2 : 4;
}

void LatencyBudget::ready_at(std::int64_t now_utime) {
  if (!started_) return;  // nothing arrived yet: nothing queued
  exempt_ = true;
  exempt_until_publish_ = now_utime - std::min(current_min_, previous_min_);
}

}  // namespace evldt
