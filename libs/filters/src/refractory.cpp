#include <limits>
#include <stdexcept>

#include "evldt/filters/noise_filters.hpp"

namespace evldt {

RefractoryFilter::RefractoryFilter(SensorSize sensor, Timestamp period_us)
    : pixels_(static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height)),
      period_us_(static_cast<std::int32_t>(period_us)),
      next_sweep_(std::numeric_limits<Timestamp>::min()) {
  check_params(period_us);
}

void RefractoryFilter::check_params(Timestamp period_us) {
  if (period_us <= 0 || period_us > 1'000'000'000)
    throw std::invalid_argument("the refractory period must be in 1 us .. 1000 s");
}

void RefractoryFilter::sweep(Timestamp t, PixelState* states) {
  if (started_) {
    // Every stored time is within 2^31 us of the last sweep: decoded against it, exactly.
    const auto swept = static_cast<std::uint32_t>(swept_ - origin_);
    const auto horizon = static_cast<std::uint32_t>(t - kHorizonUs - origin_);
    for (std::size_t i = 0; i < pixels_; ++i) {
      std::uint32_t& last = states[i].refractory;
      if (t - (swept_ + static_cast<std::int32_t>(last - swept)) > kHorizonUs) last = horizon;
    }
  } else {
    started_ = true;
    origin_ = t - kHorizonUs;
  }
  swept_ = t;
  next_sweep_ = t + kSweepUs;
}

}  // namespace evldt
