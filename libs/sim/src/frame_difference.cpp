#include "evldt/sim/frame_difference.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "evldt/sim/random.hpp"

namespace evldt {

namespace {

// Radix digit for sorting a frame's events by time: 2048 counters, three passes cover ~2 hours.
constexpr int kRadixBits = 11;
constexpr std::uint64_t kRadixMask = (std::uint64_t{1} << kRadixBits) - 1;
constexpr double kMinThreshold = 0.01;

}  // namespace

FrameDifferenceEmulator::FrameDifferenceEmulator(SensorSize sensor, const FrameDifferenceConfig& config)
    : sensor_(sensor), config_(config), counts_(std::size_t{1} << kRadixBits) {
  if (!sensor.valid()) {
    throw std::invalid_argument(sensor.range_error());
  }
  if (!(config.contrast_on > 0) || !(config.contrast_off > 0) || !(config.log_offset > 0) || config.refractory_us < 0) {
    throw std::invalid_argument("contrast thresholds and log_offset must be positive, refractory_us not negative");
  }
  for (std::size_t i = 0; i < log_of_.size(); ++i) log_of_[i] = std::log(static_cast<double>(i) + config.log_offset);
  const std::size_t pixels = static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height);
  SimRandom random(config.seed);
  threshold_on_.resize(pixels);
  threshold_off_.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    threshold_on_[i] = std::max(kMinThreshold, config.contrast_on + config.contrast_sigma * random.normal());
    threshold_off_[i] = std::max(kMinThreshold, config.contrast_off + config.contrast_sigma * random.normal());
  }
  previous_.resize(pixels);
  reference_.resize(pixels);
  last_event_.resize(pixels);
}

void FrameDifferenceEmulator::add_frame(std::span<const std::uint8_t> grey, Timestamp t_us, EventBatch& out) {
  if (grey.size() != previous_.size()) {
    throw std::invalid_argument("frame has " + std::to_string(grey.size()) + " pixels, the sensor " +
                                std::to_string(previous_.size()));
  }
  if (frames_ > 0 && t_us <= previous_t_) {
    throw std::invalid_argument("frame time " + std::to_string(t_us) + " us is not after the previous frame's " +
                                std::to_string(previous_t_) + " us");
  }
  if (frames_ == 0) {
    std::copy(grey.begin(), grey.end(), previous_.begin());
    for (std::size_t i = 0; i < grey.size(); ++i) reference_[i] = log_of_[grey[i]];
    // As if each pixel last fired a full refractory period before the first frame: nothing is lost to it.
    std::fill(last_event_.begin(), last_event_.end(), t_us - config_.refractory_us);
    previous_t_ = t_us;
    ++frames_;
    return;
  }

  const Timestamp t_prev = previous_t_;
  const double span = static_cast<double>(t_us - t_prev);
  std::size_t i = 0;
  for (int y = 0; y < sensor_.height; ++y) {
    for (int x = 0; x < sensor_.width; ++x, ++i) {
      if (grey[i] == previous_[i]) continue;
      const double before = log_of_[previous_[i]], after = log_of_[grey[i]];
      previous_[i] = grey[i];
      const bool brighter = after > before;
      const double step = brighter ? threshold_on_[i] : -threshold_off_[i];
      const auto polarity = static_cast<std::int8_t>(brighter ? 1 : -1);
      double& reference = reference_[i];
      // The previous frame left `before` strictly within a threshold of the reference, so every level
      // reached here lies in (before, after] and its fraction of the interval in (0, 1].
      for (double level = reference + step; brighter ? level <= after : level >= after; level = reference + step) {
        reference = level;
        const double fraction = (level - before) / (after - before);
        const Timestamp t = t_prev + std::max<Timestamp>(1, static_cast<Timestamp>(std::llround(fraction * span)));
        if (t - last_event_[i] < config_.refractory_us) continue;  // lost, but the reference has moved
        last_event_[i] = t;
        pending_.push_back({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), polarity});
      }
    }
  }

  sort_pending(t_prev, t_us - t_prev);
  for (const Event& e : pending_) out.push_back(e);
  events_ += pending_.size();
  pending_.clear();
  previous_t_ = t_us;
  ++frames_;
}

void FrameDifferenceEmulator::sort_pending(Timestamp t_prev, Timestamp span) {
  // LSD radix sort on the offset into the frame interval: stable, so ties stay in pixel order, and
  // unlike std::stable_sort it needs no buffer beyond the members.
  const auto largest = static_cast<std::uint64_t>(span - 1);
  sorted_.resize(pending_.size());
  for (int shift = 0; shift == 0 || (shift < 64 && (largest >> shift) != 0); shift += kRadixBits) {
    auto digit = [&](const Event& e) { return (static_cast<std::uint64_t>(e.t - t_prev - 1) >> shift) & kRadixMask; };
    std::fill(counts_.begin(), counts_.end(), 0);
    for (const Event& e : pending_) ++counts_[digit(e)];
    std::size_t start = 0;
    for (std::size_t& count : counts_) start += std::exchange(count, start);
    for (const Event& e : pending_) sorted_[counts_[digit(e)]++] = e;
    pending_.swap(sorted_);
  }
}

}  // namespace evldt
