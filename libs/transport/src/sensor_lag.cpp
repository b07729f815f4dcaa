#include "evldt/transport/sensor_lag.hpp"

namespace evldt {

void SensorLag::published(Timestamp newest_event_us, std::int64_t wall_us) {
  (void)offset_.stride(newest_event_us, wall_us);
  const std::int64_t lag_us = offset_.last_queueing_us();
  clock_offset_s_ = static_cast<double>(wall_us - newest_event_us - lag_us) * 1e-6;
  lags_.add(static_cast<double>(lag_us) * 1e-3);
}

}  // namespace evldt
