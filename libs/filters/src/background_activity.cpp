#include <limits>
#include <stdexcept>

#include "evldt/filters/noise_filters.hpp"

namespace evldt {

BackgroundActivityFilter::BackgroundActivityFilter(SensorSize sensor, Timestamp window_us, double min_noise_hz)
    : window_us_(static_cast<std::uint32_t>(window_us)),
      stride_(static_cast<std::ptrdiff_t>(surface_stride(sensor))),
      min_uncorrelated_(min_noise_hz * static_cast<double>(kJudgeUs) * 1e-6 * static_cast<double>(sensor.width) *
                        static_cast<double>(sensor.height)),
      judge_end_(std::numeric_limits<Timestamp>::min()) {
  check_params(window_us, min_noise_hz);
}

void BackgroundActivityFilter::check_params(Timestamp window_us, double min_noise_hz) {
  if (window_us <= 0 || window_us > 1'000'000'000)
    throw std::invalid_argument("the background-activity window must be in 1 us .. 1000 s");
  if (!(min_noise_hz >= 0)) throw std::invalid_argument("the background-activity noise level must not be negative");
}

void BackgroundActivityFilter::judge(Timestamp t) {
  if (!started_) {
    // Before the first event nothing fired: a zeroed cell lies a window and a microsecond before it.
    started_ = true;
    origin_ = static_cast<std::uint32_t>(t) - window_us_ - 1;
    judge_end_ = t + kJudgeUs;
    active_ = min_uncorrelated_ <= 0;
    return;
  }
  // The uncorrelated events of the last period, per pixel and second, say whether the sensor is noisy.
  active_ = static_cast<double>(uncorrelated_) >= min_uncorrelated_;
  uncorrelated_ = 0;
  judge_end_ = t - judge_end_ < kJudgeUs ? judge_end_ + kJudgeUs : t + kJudgeUs;
}

}  // namespace evldt
