#pragma once
// The noise filters a pipeline runs before storage, built from a configuration and applied in the
// configured order; what each dropped is counted under its name.

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "evldt/filters/noise_filters.hpp"

namespace evldt {

struct FilterConfig {
  /// Filters in the order they run: "hot-pixel", "background-activity", "refractory", "anti-flicker".
  std::vector<std::string> chain = {"hot-pixel", "anti-flicker", "background-activity"};
  Timestamp background_window_us = 5000;  ///< tuned on boxes-6dof, clean and noisy (README)
  double background_min_noise_hz = 1.0;    ///< background-activity drops only above this uncorrelated rate per pixel
  Timestamp refractory_us = 100;
  HotPixelParams hot_pixel;
  AntiFlickerParams anti_flicker;
};

/// The filter names evldt knows, in their suggested order.
const std::vector<std::string>& filter_names();
/// "none" or an empty text: no filter; else names separated by commas. Throws std::invalid_argument
/// naming an unknown or repeated filter.
std::vector<std::string> parse_filter_chain(const std::string& text);
/// "hot-pixel,background-activity", or "none".
std::string format_filter_chain(const std::vector<std::string>& chain);

/// Throws std::invalid_argument, with the reason, for a configuration a chain cannot be built from.
void check_filter_config(const FilterConfig& config);

/// Events in and passed, and dropped by each filter.
struct FilterCounts {
  std::uint64_t events_in = 0;
  std::uint64_t passed = 0;
  std::uint64_t hot_pixel = 0;
  std::uint64_t background_activity = 0;
  std::uint64_t refractory = 0;
  std::uint64_t anti_flicker = 0;
  [[nodiscard]] std::uint64_t dropped() const { return hot_pixel + background_activity + refractory + anti_flicker; }
  FilterCounts& operator+=(const FilterCounts& other) {
    events_in += other.events_in;
    passed += other.passed;
    hot_pixel += other.hot_pixel;
    background_activity += other.background_activity;
    refractory += other.refractory;
    anti_flicker += other.anti_flicker;
    return *this;
  }
};

class FilterChain {
 public:
  /// Throws std::invalid_argument for an unknown filter or a parameter out of range.
  FilterChain(const FilterConfig& config, SensorSize sensor);
  /// Writes to `out` the events of `in` (on-sensor, in time order) that pass every filter, in order;
  /// `out` may be `in`. The chain must not be empty.
  void filter(const EventBatch& in, EventBatch& out);
  [[nodiscard]] bool empty() const { return filters_.empty(); }
  [[nodiscard]] FilterCounts counts() const;
  /// The pixels the hot-pixel filter masks now (y * width + x); empty without that filter.
  [[nodiscard]] std::span<const std::uint32_t> masked_pixels() const;

 private:
  std::vector<std::unique_ptr<EventFilter>> filters_;
  const HotPixelFilter* hot_pixel_ = nullptr;
  std::uint64_t events_in_ = 0, passed_ = 0;
};

}  // namespace evldt
