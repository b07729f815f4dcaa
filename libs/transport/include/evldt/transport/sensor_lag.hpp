#pragma once
// How far a live camera's batches are behind its sensor: the sensor's clock (event time)
// against the wall clock when a batch is published. The two clocks' offset is the least difference
// seen lately (judged as LatencyBudget judges queueing: over one to two windows of 2 s, so a drift
// or a step is forgotten); a batch's lag is its own difference less that offset: the time its
// newest event spent between the sensor and the publish, beyond the quickest batch's.

#include <cstdint>

#include "evldt/events/event.hpp"
#include "evldt/transport/latency_budget.hpp"
#include "evldt/transport/latency_tracker.hpp"

namespace evldt {

class SensorLag {
 public:
  /// A batch whose newest event is `newest_event_us` (sensor clock) was published at `wall_us`.
  void published(Timestamp newest_event_us, std::int64_t wall_us);
  /// The sensor's clock jumped (a camera restart, a clock reset): its offset is learnt afresh.
  void restart() { offset_ = LatencyBudget(0); }
  /// Wall clock minus sensor clock, in seconds, as last estimated (0 before any batch).
  [[nodiscard]] double clock_offset_s() const { return clock_offset_s_; }
  /// Median and p99 of the lags since the previous call, and of the whole run.
  LatencySummary take_summary() { return lags_.take_summary(); }
  [[nodiscard]] LatencySummary run_summary() const { return lags_.run_summary(); }

 private:
  LatencyBudget offset_{0};  // its budget is never used: it only estimates the least difference
  LatencyStatistics lags_;
  double clock_offset_s_ = 0;
};

}  // namespace evldt
