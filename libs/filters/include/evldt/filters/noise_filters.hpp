#pragma once
// The noise filters (docs/design.md, section 2):
//   background-activity: the spatio-temporal correlation filter; an event passes when its pixel or
//     one of its 8 neighbours fired within a time window (isolated thermal / leak events did not),
//     while the sensor is noisy enough for that to pay;
//   refractory: a pixel's events closer than a period to its previous passed one are dropped;
//   hot-pixel: learns pixels that fire far above their neighbourhood and masks them, releasing a
//     pixel that cools;
//   anti-flicker: locks onto a pixel's periodic bursts in a frequency band (mains lights, LED PWM)
//     and drops the bursts that fall on the predicted phase; other events at that pixel pass.
//
// A filter sees on-sensor events in time order (an EventValidator runs first) and costs O(1) per
// event. Each is a small class with its parameters, counters and judging, and an inline test of one
// event against the state it keeps about the event's pixel. That state lives in the chain's table
// (filter_chain.hpp), which allocates it once, zeroed: for every filter, zero means "nothing seen".

#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt {

/// What anti-flicker keeps about one pixel and polarity, 12 bytes. Times are the low 32 bits of us:
/// differences are exact for gaps under 71 minutes.
struct FlickerBurst {
  std::uint32_t start;  // time of the current burst's first event
  std::uint32_t last_event;
  std::uint16_t period;  // us, the locked or candidate period
  std::uint8_t streak;   // consistent periods in a row
  std::uint8_t flags;    // AntiFlickerFilter::kSeen, kFlickerBurst
};

/// What refractory and anti-flicker keep about one pixel: 32 bytes (4 of them padding), two to a
/// cache line, so an event's tests touch one line (hot-pixel's counts and background-activity's
/// times, which are scanned whole or read for 8 neighbours, are planes of their own: see
/// filter_chain.hpp). Trivial: the chain's table of them is zeroed memory, every field zero, which
/// every filter reads as nothing seen; filters not in the chain leave their fields at zero.
struct alignas(32) PixelState {
  std::uint32_t refractory;  // RefractoryFilter: its last passed event's time, on the filter's clock
  FlickerBurst flicker[2];   // AntiFlickerFilter: [0] OFF, [1] ON
};
static_assert(sizeof(PixelState) == 32 && std::is_trivial_v<PixelState>);

class BackgroundActivityFilter {
 public:
  /// Drops uncorrelated events only while they come at `min_noise_hz` per pixel or more (judged over
  /// each 200 ms of event time, applied to the next): a clean sensor's uncorrelated events are mostly
  /// the sparse edges of slow or faint motion, which the lattice needs (0: always drop them).
  /// Throws std::invalid_argument for a window not in 1 us .. 1000 s or a negative noise level.
  BackgroundActivityFilter(SensorSize sensor, Timestamp window_us, double min_noise_hz);
  /// The parameter checks of the constructor, for a configuration checked before any filter is built.
  static void check_params(Timestamp window_us, double min_noise_hz);

  /// Row stride of the surface of last-event times the filter reads: the sensor with a one-pixel
  /// border, so neighbours need no bounds checks.
  [[nodiscard]] static std::size_t surface_stride(SensorSize sensor) {
    return static_cast<std::size_t>(sensor.width) + 2;
  }
  [[nodiscard]] static std::size_t surface_size(SensorSize sensor) {
    return surface_stride(sensor) * (static_cast<std::size_t>(sensor.height) + 2);
  }

  /// The test of an event at time t whose pixel's cell of the surface is `centre`.
  [[gnu::always_inline]] bool pass(Timestamp t, std::uint32_t* centre) {
    if (t >= judge_end_) [[unlikely]]
      judge(t);  // before the test: it uses none of what judging changes
    const auto now = static_cast<std::uint32_t>(t) - origin_;
    const std::ptrdiff_t s = stride_;
    const auto recent = [&](std::uint32_t last) { return now - last <= window_us_; };
    // The pixel itself counts as support: a real edge often crosses a pixel's threshold twice in a
    // row, an isolated noise event rarely does (measured: on boxes-6dof this keeps F@1% at or above
    // no filter where the 8 neighbours alone cost 0.04 at a 10 ms window).
    // (Short-circuit: measured faster than reading all nine without branches, noisy scenes included.)
    const bool correlated = recent(centre[0]) || recent(centre[-s - 1]) || recent(centre[-s]) ||
                            recent(centre[-s + 1]) || recent(centre[-1]) || recent(centre[1]) ||
                            recent(centre[s - 1]) || recent(centre[s]) || recent(centre[s + 1]);
    *centre = now;
    uncorrelated_ += correlated ? 0 : 1;
    if (correlated || !active_) return true;
    ++dropped_;
    return false;
  }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 private:
  /// The first event starts the clock; each later one at or past the end of a judging period
  /// closes it.
  void judge(Timestamp t);

  std::uint32_t window_us_;
  std::ptrdiff_t stride_;
  // A cell holds the low 32 bits of its pixel's last event time (passed or not) minus origin_:
  // half the memory traffic of full times, and differences are exact for gaps under 71 minutes.
  // origin_ is a window before the first event, so a zeroed cell has not fired.
  std::uint32_t origin_ = 0;
  bool started_ = false;
  static constexpr Timestamp kJudgeUs = 200'000;
  double min_uncorrelated_;  // per judging period
  Timestamp judge_end_;      // the lowest time until the first event
  std::uint64_t uncorrelated_ = 0;
  bool active_ = true;
  std::uint64_t dropped_ = 0;
};

class RefractoryFilter {
 public:
  /// Throws std::invalid_argument for a period not in 1 us .. 1000 s.
  RefractoryFilter(SensorSize sensor, Timestamp period_us);
  /// The parameter check of the constructor, for a configuration checked before any filter is built.
  static void check_params(Timestamp period_us);

  /// The test of an event at time t at pixel `pixel` (y * width + x) of `states` (the chain's table).
  [[gnu::always_inline]] bool pass(Timestamp t, std::uint32_t pixel, PixelState* states) {
    if (t >= next_sweep_) [[unlikely]]
      sweep(t, states);
    std::uint32_t& last = states[pixel].refractory;
    const auto now = static_cast<std::uint32_t>(t - origin_);
    // Exact: every stored time is within 2^31 us of t (see sweep()).
    if (static_cast<std::int32_t>(now - last) < period_us_) {
      ++dropped_;
      return false;
    }
    last = now;
    return true;
  }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 private:
  /// At the first event, starts the clock; later, every kSweepUs of event time, moves each time
  /// older than kHorizonUs up to kHorizonUs before t. Such a pixel passes its next event either
  /// way (the period is below the horizon), and stored times stay within 2^31 us of any event up to
  /// the next sweep, so 32-bit differences are exact for any gap (and for time going back by up to
  /// 2^30 us).
  void sweep(Timestamp t, PixelState* states);

  static constexpr Timestamp kHorizonUs = Timestamp{1} << 30, kSweepUs = Timestamp{1} << 29;
  std::size_t pixels_;
  std::int32_t period_us_;
  // Stored times are the low 32 bits of (t - origin_); origin_ is kHorizonUs before the first
  // event, so a zeroed state has not fired for that long.
  Timestamp origin_ = 0;
  Timestamp swept_ = 0;   // the last sweep
  Timestamp next_sweep_;  // the lowest time until the first event
  bool started_ = false;
  std::uint64_t dropped_ = 0;
};

struct HotPixelParams {
  Timestamp window_us = 200'000;  ///< a pixel's rate is judged over windows of this much event time
  double min_rate_hz = 200;       ///< below this rate a pixel is never hot
  double neighbour_ratio = 8;     ///< hot: above this many times the mean rate of its 8 neighbours (+1 event)
};

/// Throws std::invalid_argument, with the reason, for parameters a filter cannot run with.
void check_params(const HotPixelParams& params);

class HotPixelFilter {
 public:
  HotPixelFilter(SensorSize sensor, const HotPixelParams& params);

  /// The test of an event at time t at pixel `pixel` (y * width + x) of `counts` (the chain's plane
  /// of counts, one per pixel): counts the event, after judging the window it ends.
  [[gnu::always_inline]] bool pass(Timestamp t, std::uint32_t pixel, std::uint32_t* counts) {
    if (t >= window_end_) [[unlikely]]
      end_window(t, counts);
    std::uint32_t& count = counts[pixel];
    ++count;  // the count stays far below kMasked: a window of a few seconds at any real rate
    if ((count & kMasked) == 0) return true;
    ++dropped_;
    return false;
  }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }
  /// The masked pixels (y * width + x): those still masked in the order they were masked, then
  /// those masked at the last judging in pixel order.
  [[nodiscard]] std::span<const std::uint32_t> masked_pixels() const { return masked_list_; }

 private:
  static constexpr std::uint32_t kMasked = 0x80000000u;  // in a count: the pixel is masked
  /// The first event starts the first window; a later one at or past its end judges it (masks the
  /// pixels that were hot in it, releases those that cooled) and starts the next. One pass down the
  /// plane of counts, which is a ninth of the records' size: a list of the pixels touched, judged
  /// in the order they came, read the table all over and stalled storage for 10 ms at 1280x720.
  void end_window(Timestamp t, std::uint32_t* counts);

  SensorSize sensor_;
  HotPixelParams params_;
  std::uint32_t min_count_, release_count_;
  Timestamp window_end_;  // the lowest time until the first event
  bool started_ = false;
  std::vector<std::uint32_t> masked_list_;
  std::vector<std::uint32_t> still_masked_;  // scratch of end_window
  std::uint64_t dropped_ = 0;
};

struct AntiFlickerParams {
  double min_hz = 50;             ///< the band of flicker frequencies (mains lights flicker at 100 or
  double max_hz = 520;            ///< 120 Hz, LED PWM up to some hundreds of Hz)
  int lock_periods = 3;           ///< consistent periods in a row before a pixel's bursts count as flicker
  double tolerance = 0.1;         ///< of a period, for a burst to fall on the predicted phase
  Timestamp burst_gap_us = 1000;  ///< events of one polarity closer than this at a pixel are one burst
};

void check_params(const AntiFlickerParams& params);

class AntiFlickerFilter {
 public:
  explicit AntiFlickerFilter(const AntiFlickerParams& params);

  /// The test of an event at time t whose pixel and polarity's state is `burst`.
  [[gnu::always_inline]] bool pass(Timestamp t, FlickerBurst& burst) {
    const auto now = static_cast<std::uint32_t>(t);
    if ((burst.flags & kSeen) != 0 && now - burst.last_event <= burst_gap_us_) {
      burst.last_event = now;  // the same burst: the verdict of its first event
      if ((burst.flags & kFlickerBurst) == 0) return true;
      ++dropped_;
      return false;
    }
    if (new_burst(now, burst)) return true;
    ++dropped_;
    return false;
  }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 private:
  static constexpr std::uint8_t kSeen = 1, kFlickerBurst = 2;
  /// The first event of a burst: whether it (and so its burst) passes.
  bool new_burst(std::uint32_t now, FlickerBurst& burst);
  [[nodiscard]] bool near(std::uint32_t since, std::uint32_t expected) const;

  AntiFlickerParams params_;
  std::uint32_t burst_gap_us_;
  std::uint32_t min_period_, max_period_;
  std::uint64_t dropped_ = 0;
};

// Inline, so that the chain's pass inlines it too (measured: 5-8% faster).
inline bool AntiFlickerFilter::near(std::uint32_t since, std::uint32_t expected) const {
  const std::uint32_t error = since > expected ? since - expected : expected - since;
  return static_cast<double>(error) <= params_.tolerance * static_cast<double>(expected) + 1.0;
}

inline bool AntiFlickerFilter::new_burst(std::uint32_t now, FlickerBurst& burst) {
  if ((burst.flags & kSeen) == 0) {
    burst = FlickerBurst{now, now, 0, 0, kSeen};
    return true;
  }
  burst.flags = kSeen;
  burst.last_event = now;
  const std::uint32_t since = now - burst.start;
  const auto lock = static_cast<std::uint8_t>(params_.lock_periods);
  if (burst.streak >= lock) {
    // Locked: a burst one to three periods after the last flicker burst, on its phase, is flicker;
    // any other is a real change at this pixel (an edge passing under the light) and passes
    // without moving the phase.
    const std::uint32_t period = burst.period;
    const std::uint32_t n = (since + period / 2) / period;
    if (n >= 1 && n <= 3 && near(since, n * period)) {
      if (n == 1 && since <= max_period_)
        burst.period = static_cast<std::uint16_t>(since);  // follows a drifting frequency
      burst.start = now;
      burst.flags |= kFlickerBurst;
      return false;
    }
    if (since > 4 * period) {  // the flicker stopped: acquire afresh from this burst
      burst.streak = 0;
      burst.start = now;
    }
    return true;
  }
  // Acquiring: consecutive bursts at a steady period inside the band.
  if (since >= min_period_ && since <= max_period_) {
    burst.streak =
        burst.streak > 0 && near(since, burst.period) ? static_cast<std::uint8_t>(burst.streak + 1) : std::uint8_t{1};
    burst.period = static_cast<std::uint16_t>(since);
  } else {
    burst.streak = 0;
  }
  burst.start = now;
  if (burst.streak < lock) return true;
  burst.flags |= kFlickerBurst;
  return false;
}

}  // namespace evldt
