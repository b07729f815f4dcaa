#include <algorithm>
#include <limits>
#include <stdexcept>

#include "evldt/filters/noise_filters.hpp"

namespace evldt {

// Never within a window of any event time, without overflow when the window is subtracted.
constexpr Timestamp kNever = std::numeric_limits<Timestamp>::min() / 2;

BackgroundActivityFilter::BackgroundActivityFilter(SensorSize sensor, Timestamp window_us, double min_noise_hz)
    : EventFilter(sensor),
      window_us_(static_cast<std::uint32_t>(window_us)),
      stride_(sensor.width + 2),
      last_event_(static_cast<std::size_t>(sensor.width + 2) * static_cast<std::size_t>(sensor.height + 2), 0),
      min_uncorrelated_(min_noise_hz * static_cast<double>(kJudgeUs) * 1e-6 * static_cast<double>(pixels())) {
  if (window_us <= 0 || window_us > 1'000'000'000) throw std::invalid_argument("the background-activity window must be in 1 us .. 1000 s");
  if (!(min_noise_hz >= 0)) throw std::invalid_argument("the background-activity noise level must not be negative");
}

void BackgroundActivityFilter::filter(const EventBatch& in, EventBatch& out) {
  const std::ptrdiff_t s = stride_;
  if (!started_ && !in.empty()) {
    // Before the first event nothing fired: every pixel's last event lies a window before it.
    std::fill(last_event_.begin(), last_event_.end(), static_cast<std::uint32_t>(in.t.front()) - window_us_ - 1);
    started_ = true;
    judge_end_ = in.t.front() + kJudgeUs;
    active_ = min_uncorrelated_ <= 0;
  }
  keep_if(in, out, [&](Timestamp t, std::uint16_t x, std::uint16_t y, std::int8_t) {
    std::uint32_t* centre = last_event_.data() + (static_cast<std::ptrdiff_t>(y) + 1) * s + x + 1;
    const auto now = static_cast<std::uint32_t>(t);
    const auto recent = [&](std::uint32_t last) { return now - last <= window_us_; };
    // The pixel itself counts as support: a real edge often crosses a pixel's threshold twice in a
    // row, an isolated noise event rarely does (measured: on boxes-6dof this keeps F@1% at or above
    // no filter where the 8 neighbours alone cost 0.04 at a 10 ms window).
    const bool correlated = recent(centre[0]) || recent(centre[-s - 1]) || recent(centre[-s]) || recent(centre[-s + 1]) ||
                            recent(centre[-1]) || recent(centre[1]) || recent(centre[s - 1]) || recent(centre[s]) ||
                            recent(centre[s + 1]);
    *centre = now;
    if (t >= judge_end_) {
      // The uncorrelated events of the last period, per pixel and second, say whether the sensor is noisy.
      active_ = static_cast<double>(uncorrelated_) >= min_uncorrelated_;
      uncorrelated_ = 0;
      judge_end_ = t - judge_end_ < kJudgeUs ? judge_end_ + kJudgeUs : t + kJudgeUs;
    }
    uncorrelated_ += correlated ? 0 : 1;
    return correlated || !active_;
  });
}

RefractoryFilter::RefractoryFilter(SensorSize sensor, Timestamp period_us)
    : EventFilter(sensor), period_us_(period_us), last_passed_(pixels(), kNever) {
  if (period_us <= 0) throw std::invalid_argument("the refractory period must be positive");
}

void RefractoryFilter::filter(const EventBatch& in, EventBatch& out) {
  keep_if(in, out, [&](Timestamp t, std::uint16_t x, std::uint16_t y, std::int8_t) {
    Timestamp& last = last_passed_[pixel(x, y)];
    if (t - last < period_us_) return false;
    last = t;
    return true;
  });
}

}  // namespace evldt
