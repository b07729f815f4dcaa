#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "evldt/filters/noise_filters.hpp"

namespace evldt {
namespace {
constexpr std::uint8_t kSeen = 1, kFlickerBurst = 2;
}  // namespace

AntiFlickerFilter::AntiFlickerFilter(SensorSize sensor, const AntiFlickerParams& params)
    : EventFilter(sensor), params_(params), bursts_(pixels() * 2) {
  check_params(params);
  min_period_ = static_cast<std::uint32_t>(std::lround(1e6 / params.max_hz));
  max_period_ = static_cast<std::uint32_t>(std::lround(1e6 / params.min_hz));  // under 62500: fits the 16-bit period
}

void check_params(const AntiFlickerParams& params) {
  if (!(params.min_hz > 16) || !(params.max_hz > params.min_hz) || params.lock_periods < 1 || params.lock_periods > 255 ||
      !(params.tolerance > 0 && params.tolerance < 0.5) || params.burst_gap_us <= 0) {
    throw std::invalid_argument("anti-flicker: a band above 16 Hz (its lowest below its highest), 1-255 lock periods, a "
                                "tolerance in (0, 0.5) and a positive burst gap");
  }
}

bool AntiFlickerFilter::near(std::uint32_t since, std::uint32_t expected) const {
  const std::uint32_t error = since > expected ? since - expected : expected - since;
  return static_cast<double>(error) <= params_.tolerance * static_cast<double>(expected) + 1.0;
}

bool AntiFlickerFilter::pass(Timestamp t, std::size_t pixel, bool on) {
  Burst& burst = bursts_[pixel * 2 + (on ? 1 : 0)];
  const auto now = static_cast<std::uint32_t>(t);
  if ((burst.flags & kSeen) != 0 && now - burst.last_event <= static_cast<std::uint32_t>(params_.burst_gap_us)) {
    burst.last_event = now;  // the same burst: the verdict of its first event
    return (burst.flags & kFlickerBurst) == 0;
  }
  if ((burst.flags & kSeen) == 0) {
    burst = Burst{now, now, 0, 0, kSeen};
    return true;
  }
  burst.flags = kSeen;
  burst.last_event = now;
  const std::uint32_t since = now - burst.start;
  const auto lock = static_cast<std::uint8_t>(params_.lock_periods);
  if (burst.streak >= lock) {
    // Locked: a burst one to three periods after the last flicker burst, on its phase, is flicker;
    // any other is a real change at this pixel (an edge passing under the light) and passes
    // without moving the phase.
    const std::uint32_t period = burst.period;
    const std::uint32_t n = (since + period / 2) / period;
    if (n >= 1 && n <= 3 && near(since, n * period)) {
      if (n == 1 && since <= max_period_) burst.period = static_cast<std::uint16_t>(since);  // follows a drifting frequency
      burst.start = now;
      burst.flags |= kFlickerBurst;
      return false;
    }
    if (since > 4 * period) {  // the flicker stopped: acquire afresh from this burst
      burst.streak = 0;
      burst.start = now;
    }
    return true;
  }
  // Acquiring: consecutive bursts at a steady period inside the band.
  if (since >= min_period_ && since <= max_period_) {
    burst.streak = burst.streak > 0 && near(since, burst.period) ? static_cast<std::uint8_t>(burst.streak + 1) : std::uint8_t{1};
    burst.period = static_cast<std::uint16_t>(since);
  } else {
    burst.streak = 0;
  }
  burst.start = now;
  if (burst.streak < lock) return true;
  burst.flags |= kFlickerBurst;
  return false;
}

void AntiFlickerFilter::filter(const EventBatch& in, EventBatch& out) {
  keep_if(in, out, [&](Timestamp t, std::uint16_t x, std::uint16_t y, std::int8_t p) { return pass(t, pixel(x, y), p > 0); });
}

}  // namespace evldt
