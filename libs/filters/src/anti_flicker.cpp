#include <cmath>
#include <stdexcept>

#include "evldt/filters/noise_filters.hpp"

namespace evldt {

AntiFlickerFilter::AntiFlickerFilter(const AntiFlickerParams& params) : params_(params) {
  check_params(params);
  burst_gap_us_ = static_cast<std::uint32_t>(params.burst_gap_us);
  min_period_ = static_cast<std::uint32_t>(std::lround(1e6 / params.max_hz));
  max_period_ = static_cast<std::uint32_t>(std::lround(1e6 / params.min_hz));  // under 62500: fits the 16-bit period
}

void check_params(const AntiFlickerParams& params) {
  if (!(params.min_hz > 16) || !(params.max_hz > params.min_hz) || params.lock_periods < 1 ||
      params.lock_periods > 255 || !(params.tolerance > 0 && params.tolerance < 0.5) || params.burst_gap_us <= 0) {
    throw std::invalid_argument(
        "anti-flicker: a band above 16 Hz (its lowest below its highest), 1-255 lock periods, a "
        "tolerance in (0, 0.5) and a positive burst gap");
  }
}

}  // namespace evldt
