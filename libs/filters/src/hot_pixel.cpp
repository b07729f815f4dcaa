#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "evldt/filters/noise_filters.hpp"

namespace evldt {

HotPixelFilter::HotPixelFilter(SensorSize sensor, const HotPixelParams& params)
    : sensor_(sensor),
      params_(params),
      min_count_(static_cast<std::uint32_t>(
          std::max(2.0, std::ceil(params.min_rate_hz * static_cast<double>(params.window_us) * 1e-6)))),
      release_count_(std::max<std::uint32_t>(1, min_count_ / 2)),
      window_end_(std::numeric_limits<Timestamp>::min()) {
  check_params(params);
}

void check_params(const HotPixelParams& params) {
  if (params.window_us <= 0 || !(params.min_rate_hz > 0) || !(params.neighbour_ratio >= 1)) {
    throw std::invalid_argument("hot-pixel window and rate must be positive and the neighbour ratio at least 1");
  }
}

void HotPixelFilter::end_window(Timestamp t, std::uint32_t* counts) {
  if (!started_) {
    started_ = true;
    window_end_ = t + params_.window_us;
    return;
  }
  // A masked pixel stays masked while it still fires at half the hot rate; below that it has cooled.
  still_masked_.clear();
  for (const std::uint32_t i : masked_list_) {
    if ((counts[i] & ~kMasked) >= release_count_) {
      still_masked_.push_back(i);
    } else {
      counts[i] &= ~kMasked;
    }
  }
  masked_list_.swap(still_masked_);
  const int width = sensor_.width, height = sensor_.height;
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  for (std::size_t i = 0; i < pixels; ++i) {
    // Unmasked with at least min_count_ events (a masked count is kMasked or more).
    if (counts[i] - min_count_ >= kMasked - min_count_) continue;
    const std::uint32_t count = counts[i];
    const int x = static_cast<int>(i % static_cast<std::size_t>(width)),
              y = static_cast<int>(i / static_cast<std::size_t>(width));
    std::uint64_t sum = 0;
    int neighbours = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
        sum += counts[static_cast<std::size_t>(ny) * static_cast<std::size_t>(width) + static_cast<std::size_t>(nx)] &
               ~kMasked;
        ++neighbours;
      }
    }
    const double neighbour_mean = static_cast<double>(sum) / std::max(neighbours, 1);
    if (static_cast<double>(count) > params_.neighbour_ratio * (neighbour_mean + 1.0))
      masked_list_.push_back(static_cast<std::uint32_t>(i));
  }
  std::fill(counts, counts + pixels, std::uint32_t{0});
  for (const std::uint32_t i : masked_list_) counts[i] = kMasked;
  // The next window follows on, unless a gap in event time left it behind.
  window_end_ = t - window_end_ < params_.window_us ? window_end_ + params_.window_us : t + params_.window_us;
}

}  // namespace evldt
