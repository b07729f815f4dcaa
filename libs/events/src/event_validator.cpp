#include "evldt/events/event_validator.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <bit>
#include <limits>

namespace evldt {

EventValidator::EventValidator(SensorSize sensor, Timestamp backwards_slack_us)
    : sensor_(sensor), slack_(backwards_slack_us), newest_(std::numeric_limits<Timestamp>::min()) {}

namespace {

// Events checked together by the fast path: a block's columns stay in L1 for the copy that
// compacts them after a drop.
constexpr std::size_t kBlock = 512;

/// Whether the events [begin, end) are all on the sensor (x <= x_max, y <= y_max) and in time order
/// (each no earlier than the one before). Branch-free, so that it vectorises.
bool on_sensor_and_in_order(const EventBatch& batch, std::size_t begin, std::size_t end, std::uint16_t x_max,
                            std::uint16_t y_max) {
  const std::uint16_t* x = batch.x.data();
  const std::uint16_t* y = batch.y.data();
  unsigned off = 0;
  for (std::size_t i = begin; i < end; ++i)
    off |= static_cast<unsigned>(x[i] > x_max) | static_cast<unsigned>(y[i] > y_max);
  // t[i] < t[i-1], as the sign bit of the overflow-corrected difference (SSE2 has no 64-bit compare).
  const Timestamp* t = batch.t.data();
  std::uint64_t back = 0;
  for (std::size_t i = begin + 1; i < end; ++i) {
    const auto a = static_cast<std::uint64_t>(t[i]), b = static_cast<std::uint64_t>(t[i - 1]);
    const std::uint64_t difference = a - b;
    back |= difference ^ ((a ^ b) & (difference ^ a));
  }
  return off == 0 && (back >> 63) == 0;
}

}  // namespace

std::size_t EventValidator::filter(EventBatch& batch) {
  std::size_t kept = 0;
  const std::size_t n = batch.size();
  // The fast path takes a whole block that this loop would keep event by event without a warning:
  // every event on the sensor, in time order, the first not behind the newest by more than the slack
  // (the others then cannot be). A sensor side of 0 keeps nothing: no fast path.
  const bool fast = sensor_.width > 0 && sensor_.height > 0 && slack_ >= 0;
  const auto x_max = static_cast<std::uint16_t>(std::min(sensor_.width, 1 << 16) - 1);
  const auto y_max = static_cast<std::uint16_t>(std::min(sensor_.height, 1 << 16) - 1);
  std::size_t i = 0;
  while (i < n) {
    const std::size_t block_end = std::min(n, i + kBlock);
    if (fast && (newest_ == std::numeric_limits<Timestamp>::min() || batch.t[i] >= newest_ - slack_) &&
        on_sensor_and_in_order(batch, i, block_end, x_max, y_max)) {
      if (kept != i) {
        const auto move = [&](auto& column) {
          std::copy(column.begin() + static_cast<std::ptrdiff_t>(i),
                    column.begin() + static_cast<std::ptrdiff_t>(block_end),
                    column.begin() + static_cast<std::ptrdiff_t>(kept));
        };
        move(batch.t);
        move(batch.x);
        move(batch.y);
        move(batch.p);
      }
      newest_ = std::max(newest_, batch.t[block_end - 1]);
      backwards_run_ = 0;
      kept += block_end - i;
      i = block_end;
      continue;
    }
    for (; i < block_end; ++i) {
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
        spdlog::warn(
            "event time went back from {}us to {}us for {} events in a row: following the new clock "
            "(clock reset {})",
            newest_, t, kClockResetRun, drops_.clock_resets);
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
  }
  batch.truncate(kept);
  accepted_ += kept;
  return n - kept;
}

}  // namespace evldt
