#pragma once
// The latency budget of a live subscriber (docs/design.md, section 7: under overload): a batch that queued longer
// than the budget is thinned (every 2nd event kept, every 4th past 1.5 budgets), so that the events
// kept still span all of its time and the whole sensor, and storage catches up; one that queued
// twice the budget is shed whole (the last resort: a stretch of time without events). The lattice keeps only
// each block's newest events, so answers from a little less data beat answers a second old.
//
// Lateness is judged against the quickest delivery seen lately, not against the sender's clock
// alone: a batch's delay from its publish (the sender's wall clock) to its arrival is transit plus
// queueing plus the offset between the two clocks, and the least delay over the last seconds is
// transit and offset. So two hosts whose clocks differ (no NTP on a robot's LAN) still shed only
// what queued, and a clock step is forgotten within two windows.

#include <cstdint>

namespace evldt {

/// What a subscriber does with a batch that queued past the budget: keep a share of its events
/// (thin, and shed only past twice the budget), or shed it whole (the policy before thinning).
enum class OverloadPolicy : std::uint8_t { Thin, Shed };

class LatencyBudget {
 public:
  /// `max_latency_ms`: the queueing a batch may have met before it is thinned (OverloadPolicy::Thin)
  /// or shed (OverloadPolicy::Shed); 0 never does either.
  /// `window_us`: how long the quickest delivery is remembered (the estimate spans one to two windows).
  explicit LatencyBudget(double max_latency_ms, std::int64_t window_us = 2'000'000,
                         OverloadPolicy policy = OverloadPolicy::Thin);

  /// A batch published at `publish_utime` (sender's clock) arrives at `now_utime` (ours): how much of
  /// it to store, as every stride-th event: 1 all of it (it queued at most the budget); with
  /// OverloadPolicy::Thin 2 past the budget, 4 past 1.5 budgets and 0 (none: shed it whole) past
  /// twice; with OverloadPolicy::Shed 0 past the budget. Every arrival refines the estimate.
  int stride(std::int64_t publish_utime, std::int64_t now_utime);

  /// The consumer was not ready until `now_utime` (ours): its store was being built. Batches
  /// published before then (as judged by the quickest delivery seen) are never late: they queued
  /// behind a one-off start, not behind a consumer that cannot keep up, and an empty store is better
  /// filled with them than left empty. Their queueing is still measured.
  void ready_at(std::int64_t now_utime);

  [[nodiscard]] double max_latency_ms() const { return static_cast<double>(budget_us_) * 1e-3; }
  /// How long the last batch queued (its delay beyond the quickest delivery), in microseconds.
  [[nodiscard]] std::int64_t last_queueing_us() const { return last_queueing_us_; }

 private:
  std::int64_t budget_us_;
  std::int64_t window_us_;
  OverloadPolicy policy_;
  // The least delay of the current window and of the one before it; the estimate is their minimum.
  bool started_ = false;
  std::int64_t window_start_ = 0;
  std::int64_t current_min_ = 0, previous_min_ = 0;
  std::int64_t last_queueing_us_ = 0;
  bool exempt_ = false;
  std::int64_t exempt_until_publish_ = 0;  // sender's clock: batches published up to then are not late
};

}  // namespace evldt
