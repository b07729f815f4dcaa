#pragma once
// Paces a replay at real time or a speed factor: event time t is published at the wall-clock moment
// anchor + (t - t_anchor) / speed.

#include <atomic>
#include <chrono>

#include "evldt/events/event.hpp"

namespace evldt {

class Pacer {
 public:
  /// speed <= 0 or infinite: as fast as possible.
  explicit Pacer(double speed) : speed_(speed) {}

  /// Sleeps until event time `t` is due (the first call after construction or reanchor() anchors
  /// it to now). Wakes at least every 100 ms to honour `stop`. Returns how late it is, in seconds.
  double wait_until(Timestamp t, const std::atomic<bool>& stop);
  /// The next wait_until anchors afresh (after a loop of the recording restarts).
  void reanchor() { anchored_ = false; }

 private:
  using Clock = std::chrono::steady_clock;
  double speed_;
  bool anchored_ = false;
  Clock::time_point anchor_wall_;
  Timestamp anchor_t_ = 0;
};

}  // namespace evldt
