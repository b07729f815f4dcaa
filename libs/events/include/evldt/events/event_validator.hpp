#pragma once
// Validation of events from the outside world: events off the sensor or with time going backwards
// are dropped and counted, never stored.

#include <cstdint>

#include "evldt/events/event.hpp"

namespace evldt {

struct DropCounts {
  std::uint64_t off_sensor = 0;
  std::uint64_t time_backwards = 0;
  [[nodiscard]] std::uint64_t total() const { return off_sensor + time_backwards; }
};

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
  DropCounts drops_;
};

}  // namespace evldt
