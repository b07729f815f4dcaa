#pragma once
// The noise filters a pipeline runs before storage, built from a configuration and applied in the
// configured order; what each dropped is counted under its name.

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evldt/filters/noise_filters.hpp"

namespace evldt {

struct FilterConfig {
  /// Filters in the order they run: "hot-pixel", "background-activity", "refractory", "anti-flicker".
  std::vector<std::string> chain = {"refractory", "hot-pixel", "anti-flicker", "background-activity"};
  Timestamp background_window_us = 5000;  ///< tuned on boxes-6dof, clean and noisy (docs/accuracy.md, noise filters)
  double background_min_noise_hz = 1.0;   ///< background-activity drops only above this uncorrelated rate per pixel
  Timestamp refractory_us = 300;          ///< tuned on the built-in scenes (docs/accuracy.md, noise filters)
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

/// Throws std::invalid_argument, with the reason, for a configuration a chain cannot be built from
/// (an unknown or repeated filter, a parameter out of range).
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

namespace filter_chain_detail {
enum class Kind : std::uint8_t { HotPixel, BackgroundActivity, Refractory, AntiFlicker };
}  // namespace filter_chain_detail

class FilterChain {
 public:
  /// Throws std::invalid_argument for an unknown filter or a parameter out of range.
  FilterChain(const FilterConfig& config, SensorSize sensor);
  /// Writes to `out` the events of `in` (on-sensor, in time order) that pass every filter, in order;
  /// `out` may be `in`. The chain must not be empty. Once `out` has held a batch as large, no
  /// allocation.
  void filter(const EventBatch& in, EventBatch& out);
  [[nodiscard]] bool empty() const { return !hot_pixel_ && !background_activity_ && !refractory_ && !anti_flicker_; }
  [[nodiscard]] FilterCounts counts() const;
  /// The pixels the hot-pixel filter masks now (y * width + x); empty without that filter.
  [[nodiscard]] std::span<const std::uint32_t> masked_pixels() const;

 private:
  using Kind = filter_chain_detail::Kind;
  // One pass per batch: each event meets the filters in order until one drops it, so each filter
  // sees exactly the events the ones before it passed, in order, whatever the batch sizes.
  template <Kind... Ks>
  struct Pass;
  using PassFunction = void (*)(FilterChain&, const EventBatch&, EventBatch&);
  // An order as a number: the k-th filter's kind (counted from 1) in base-5 digit k.
  static constexpr std::size_t kOrderCodes = 5 * 5 * 5 * 5;
  template <Kind... Ks>
  static constexpr std::size_t order_code() {
    std::size_t code = 0, digit = 1;
    ((code += digit * (static_cast<std::size_t>(Ks) + 1), digit *= 5), ...);
    return code;
  }
  /// Enters the pass of every order that starts with Ks.
  template <Kind... Ks>
  static void add_passes(std::array<PassFunction, kOrderCodes>& passes);

  PassFunction pass_;
  std::optional<HotPixelFilter> hot_pixel_;
  std::optional<BackgroundActivityFilter> background_activity_;
  std::optional<RefractoryFilter> refractory_;
  std::optional<AntiFlickerFilter> anti_flicker_;
  // The per-pixel state of every filter, in one mapping the kernel zeroes (nothing seen), each part
  // only where its filter is in the chain: a 32-byte record per pixel (y * width + x) for refractory
  // and anti-flicker; hot-pixel's counts as a plane of 4-byte cells, which its judging scans whole
  // every window; background-activity's last-event times as a plane with a one-pixel border, so
  // that its 3x3 neighbourhood lies on 3 rows of 4-byte cells (3 cache lines, not the 6 its times
  // would span as part of the records).
  struct Unmap {
    std::size_t bytes;
    void operator()(std::byte* memory) const;
  };
  std::unique_ptr<std::byte, Unmap> table_;
  std::size_t counts_offset_ = 0, surface_offset_ = 0;  // bytes
  int width_;
  std::size_t surface_stride_ = 0;
  std::uint64_t events_in_ = 0, passed_ = 0;
};

}  // namespace evldt
