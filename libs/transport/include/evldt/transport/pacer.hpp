#pragma once
// Paces a replay at real time or a speed factor: event time t is published at the wall-clock moment
// anchor + (t - t_anchor) / speed. A jump of event time (forward by more than kMaxWaitedGapUs, or
// back) is not waited through: the pacer re-anchors there and counts it, so a recording with a
// corrupt timestamp or a paused stretch does not stall the camera for hours.

#include <atomic>
#include <chrono>
#include <cstdint>

#include "evldt/events/event.hpp"

namespace evldt {

class Pacer {
 public:
  static constexpr Timestamp kMaxWaitedGapUs = 10'000'000;

  /// speed <= 0 or infinite: as fast as possible.
  explicit Pacer(double speed) : speed_(speed) {}

  /// Sleeps until event time `t` is due (the first call after construction or reanchor() anchors
  /// it to now). Wakes at least every 100 ms to honour `stop`. Returns how late it is, in seconds.
  double wait_until(Timestamp t, const std::atomic<bool>& stop);
  /// The next wait_until anchors afresh (after a loop of the recording restarts).
  void reanchor() { anchored_ = false; }
  /// Jumps of event time that were not waited through.
  [[nodiscard]] std::uint64_t skipped_gaps() const { return skipped_gaps_; }

 private:
  using Clock = std::chrono::steady_clock;
  double speed_;
  bool anchored_ = false;
  Clock::time_point anchor_wall_;
  Timestamp anchor_t_ = 0;
  Timestamp last_t_ = 0;
  std::uint64_t skipped_gaps_ = 0;
};

}  // namespace evldt
