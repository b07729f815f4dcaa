#include "evldt/events/event_validator.hpp"

#include <bit>
#include <limits>
#include <spdlog/spdlog.h>

namespace evldt {

EventValidator::EventValidator(SensorSize sensor, Timestamp backwards_slack_us)
    : sensor_(sensor), slack_(backwards_slack_us), newest_(std::numeric_limits<Timestamp>::min()) {}

std::size_t EventValidator::filter(EventBatch& batch) {
  std::size_t kept = 0;
  const std::size_t n = batch.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Timestamp t = batch.t[i];
    if (!sensor_.contains(batch.x[i], batch.y[i])) {
      if (std::has_single_bit(++drops_.off_sensor)) {
        spdlog::warn("dropped {} event(s) off the {}x{} sensor (latest at x={} y={} t={}us)", drops_.off_sensor,
                     sensor_.width, sensor_.height, batch.x[i], batch.y[i], t);
      }
      continue;
    }
    if (newest_ != std::numeric_limits<Timestamp>::min() && t < newest_ - slack_) {
      if (++backwards_run_ < kClockResetRun) {
        if (std::has_single_bit(++drops_.time_backwards)) {
          spdlog::warn("dropped {} event(s) whose time went backwards by more than {}us (latest t={}us after {}us)",
                       drops_.time_backwards, slack_, t, newest_);
        }
        continue;
      }
      ++drops_.clock_resets;
      spdlog::warn("event time went back from {}us to {}us for {} events in a row: following the new clock "
                   "(clock reset {})", newest_, t, kClockResetRun, drops_.clock_resets);
      newest_ = t;
    }
    backwards_run_ = 0;
    if (t > newest_) newest_ = t;
    if (kept != i) {
      batch.t[kept] = t;
      batch.x[kept] = batch.x[i];
      batch.y[kept] = batch.y[i];
      batch.p[kept] = batch.p[i];
    }
    ++kept;
  }
  batch.truncate(kept);
  accepted_ += kept;
  return n - kept;
}

}  // namespace evldt
