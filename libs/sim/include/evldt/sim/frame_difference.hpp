#pragma once
// Event emulation from ordinary video frames: per pixel, the log intensity is taken to change
// linearly from one frame to the next; the pixel fires each time it moves a contrast threshold (C+/C-,
// with per-pixel spread) away from its reference, at the interpolated time, with a refractory period.
// Same threshold model as EventSimulator, but driven by recorded frames instead of a Scene.
// Deterministic for a seed.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt {

struct FrameDifferenceConfig {
  double contrast_on = 0.2;       ///< C+ (log intensity)
  double contrast_off = 0.2;      ///< C-
  double contrast_sigma = 0.03;   ///< per-pixel spread of both thresholds (std dev); thresholds are clamped to >= 0.01
  Timestamp refractory_us = 100;  ///< a pixel's events closer than this to its previous one are lost
  double log_offset = 1.0;        ///< log(I + log_offset) on 8-bit intensities, so black is finite
  std::uint64_t seed = 1;
};

class FrameDifferenceEmulator {
 public:
  /// Throws std::invalid_argument for an invalid or too large (> 65536) sensor, non-positive
  /// contrasts or log_offset, or a negative refractory period.
  FrameDifferenceEmulator(SensorSize sensor, const FrameDifferenceConfig& config);

  /// Appends (without clearing) to `out` the events caused by the change from the previous frame to
  /// this one, with times interpolated linearly within (previous frame time, t_us], in time order
  /// (stable: ties in pixel order). Polarity is +1 brighter, -1 darker, as Event documents. The first
  /// frame only sets the per-pixel reference and emits none. `grey` is row-major 8-bit intensity,
  /// sensor.width*sensor.height values; throws std::invalid_argument (changing nothing) if its size
  /// is wrong or t_us is not after the previous frame time.
  void add_frame(std::span<const std::uint8_t> grey, Timestamp t_us, EventBatch& out);

  [[nodiscard]] std::uint64_t frames() const { return frames_; }
  /// Events handed out so far (refractory losses not included).
  [[nodiscard]] std::uint64_t events() const { return events_; }

 private:
  void sort_pending(Timestamp t_prev, Timestamp span);

  SensorSize sensor_;
  FrameDifferenceConfig config_;
  std::array<double, 256> log_of_{};  // log(I + log_offset) for every 8-bit intensity
  std::vector<std::uint8_t> previous_;
  std::vector<double> reference_, threshold_on_, threshold_off_;
  std::vector<Timestamp> last_event_;
  Timestamp previous_t_ = 0;
  std::uint64_t frames_ = 0, events_ = 0;
  // Scratch for one frame's events, kept so steady-state frames do not allocate.
  std::vector<Event> pending_, sorted_;
  std::vector<std::size_t> counts_;
};

}  // namespace evldt
