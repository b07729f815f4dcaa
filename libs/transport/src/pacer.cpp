#include "evldt/transport/pacer.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

namespace evldt {

double Pacer::wait_until(Timestamp t, const std::atomic<bool>& stop) {
  if (!(speed_ > 0) || std::isinf(speed_)) return 0.0;
  if (anchored_ && (t - last_t_ > kMaxWaitedGapUs || t < last_t_)) {
    ++skipped_gaps_;
    anchored_ = false;
  }
  last_t_ = t;
  if (!anchored_) {
    anchored_ = true;
    anchor_wall_ = Clock::now();
    anchor_t_ = t;
    return 0.0;
  }
  const auto due = anchor_wall_ + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::micro>(
                                      static_cast<double>(t - anchor_t_) / speed_));
  constexpr auto kStopCheck = std::chrono::milliseconds(100);
  for (auto now = Clock::now(); now < due && !stop.load(std::memory_order_relaxed); now = Clock::now()) {
    std::this_thread::sleep_for(std::min<Clock::duration>(due - now, kStopCheck));
  }
  return std::max(0.0, std::chrono::duration<double>(Clock::now() - due).count());
}

}  // namespace evldt
