#pragma once
// Validation of events from the outside world: events off the sensor or with time going backwards
// are dropped and counted, never stored. A long run of events all behind the newest time means that
// time itself went back (a camera clock reset, or one corrupt event far in the future): the
// validator then follows the new clock and counts a clock reset, so one bad timestamp cannot make
// it drop the rest of a stream.

#include <cstdint>

#include "evldt/events/event.hpp"

namespace evldt {

struct DropCounts {
  std::uint64_t off_sensor = 0;
  std::uint64_t time_backwards = 0;
  std::uint64_t clock_resets = 0;  ///< times the validator followed a clock that went back (no event dropped)
  [[nodiscard]] std::uint64_t total() const { return off_sensor + time_backwards; }
};

/// Consecutive events behind the newest time (beyond the slack) after which the clock is taken to
/// have gone back: at 1 Mev/s, a millisecond of events.
inline constexpr std::uint64_t kClockResetRun = 1000;

class EventValidator {
 public:
  /// Events older than the newest accepted one by more than backwards_slack_us are dropped.
  EventValidator(SensorSize sensor, Timestamp backwards_slack_us);

  /// Removes invalid events from the batch in place (order kept) and returns how many were dropped.
  /// Logs a warning the first time each kind of drop happens, and then at every power of two.
  std::size_t filter(EventBatch& batch);

  [[nodiscard]] const DropCounts& drops() const { return drops_; }
  [[nodiscard]] Timestamp newest_time() const { return newest_; }
  [[nodiscard]] std::uint64_t accepted() const { return accepted_; }

 private:
  SensorSize sensor_;
  Timestamp slack_;
  Timestamp newest_;
  std::uint64_t accepted_ = 0;
  std::uint64_t backwards_run_ = 0;
  DropCounts drops_;
};

}  // namespace evldt
