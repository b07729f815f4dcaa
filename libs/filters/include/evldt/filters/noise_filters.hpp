#pragma once
// The noise filters (DESIGN 8: noise before storage):
//   background-activity: the spatio-temporal correlation filter; an event passes when its pixel or
//     one of its 8 neighbours fired within a time window (isolated thermal / leak events did not),
//     while the sensor is noisy enough for that to pay;
//   refractory: a pixel's events closer than a period to its previous passed one are dropped;
//   hot-pixel: learns pixels that fire far above their neighbourhood and masks them, releasing a
//     pixel that cools;
//   anti-flicker: locks onto a pixel's periodic bursts in a frequency band (mains lights, LED PWM)
//     and drops the bursts that fall on the predicted phase; other events at that pixel pass.

#include <cstdint>
#include <span>
#include <vector>

#include "evldt/filters/event_filter.hpp"

namespace evldt {

class BackgroundActivityFilter final : public EventFilter {
 public:
  /// Drops uncorrelated events only while they come at `min_noise_hz` per pixel or more (judged over
  /// each 200 ms of event time, applied to the next): a clean sensor's uncorrelated events are mostly
  /// the sparse edges of slow or faint motion, which the lattice needs (0: always drop them).
  BackgroundActivityFilter(SensorSize sensor, Timestamp window_us, double min_noise_hz);
  [[nodiscard]] std::string_view name() const override { return "background-activity"; }
  void filter(const EventBatch& in, EventBatch& out) override;

 private:
  std::uint32_t window_us_;
  int stride_;                             // the surface has a one-pixel border, so neighbours need no bounds checks
  // Per pixel, the low 32 bits of its last event's time (passed or not): half the memory traffic of
  // full times, and differences are exact for gaps under 71 minutes.
  std::vector<std::uint32_t> last_event_;
  bool started_ = false;
  static constexpr Timestamp kJudgeUs = 200'000;
  double min_uncorrelated_;      // per judging period
  Timestamp judge_end_ = 0;
  std::uint64_t uncorrelated_ = 0;
  bool active_ = true;
};

class RefractoryFilter final : public EventFilter {
 public:
  RefractoryFilter(SensorSize sensor, Timestamp period_us);
  [[nodiscard]] std::string_view name() const override { return "refractory"; }
  void filter(const EventBatch& in, EventBatch& out) override;

 private:
  Timestamp period_us_;
  std::vector<Timestamp> last_passed_;
};

struct HotPixelParams {
  Timestamp window_us = 200'000;  ///< a pixel's rate is judged over windows of this much event time
  double min_rate_hz = 200;       ///< below this rate a pixel is never hot
  double neighbour_ratio = 8;     ///< hot: above this many times the mean rate of its 8 neighbours (+1 event)
};

/// Throws std::invalid_argument, with the reason, for parameters a filter cannot run with.
void check_params(const HotPixelParams& params);

class HotPixelFilter final : public EventFilter {
 public:
  HotPixelFilter(SensorSize sensor, const HotPixelParams& params);
  [[nodiscard]] std::string_view name() const override { return "hot-pixel"; }
  void filter(const EventBatch& in, EventBatch& out) override;
  /// The masked pixels (y * width + x), in the order they were masked.
  [[nodiscard]] std::span<const std::uint32_t> masked_pixels() const { return masked_list_; }

 private:
  /// At the end of a window: masks the pixels that were hot in it, releases those that cooled.
  void judge_window();

  HotPixelParams params_;
  std::uint32_t min_count_, release_count_;
  Timestamp window_end_ = 0;
  bool started_ = false;
  // Per pixel, its events in the current window, with kMasked set while it is masked: one load per event.
  static constexpr std::uint32_t kMasked = 0x80000000u;
  std::vector<std::uint32_t> counts_;
  std::vector<std::uint32_t> touched_;       // pixels with a count, to judge and reset
  std::vector<std::uint32_t> masked_list_;
  std::vector<std::uint32_t> still_masked_;  // scratch of judge_window
};

struct AntiFlickerParams {
  double min_hz = 50;            ///< the band of flicker frequencies (mains lights flicker at 100 or
  double max_hz = 520;           ///< 120 Hz, LED PWM up to some hundreds of Hz)
  int lock_periods = 3;          ///< consistent periods in a row before a pixel's bursts count as flicker
  double tolerance = 0.1;        ///< of a period, for a burst to fall on the predicted phase
  Timestamp burst_gap_us = 1000; ///< events of one polarity closer than this at a pixel are one burst
};

void check_params(const AntiFlickerParams& params);

class AntiFlickerFilter final : public EventFilter {
 public:
  AntiFlickerFilter(SensorSize sensor, const AntiFlickerParams& params);
  [[nodiscard]] std::string_view name() const override { return "anti-flicker"; }
  void filter(const EventBatch& in, EventBatch& out) override;

 private:
  // Per pixel and polarity, 12 bytes. Times are the low 32 bits of us: differences are exact for
  // gaps under 71 minutes.
  struct Burst {
    std::uint32_t start = 0;       // time of the current burst's first event
    std::uint32_t last_event = 0;
    std::uint16_t period = 0;      // us, the locked or candidate period
    std::uint8_t streak = 0;       // consistent periods in a row
    std::uint8_t flags = 0;        // kSeen, kFlickerBurst
  };
  bool pass(Timestamp t, std::size_t pixel, bool on);
  [[nodiscard]] bool near(std::uint32_t a, std::uint32_t b) const;

  AntiFlickerParams params_;
  std::uint32_t min_period_, max_period_;
  std::vector<Burst> bursts_;  // [pixel * 2 + (on ? 1 : 0)]
};

}  // namespace evldt
