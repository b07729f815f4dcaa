#pragma once
// The noise filters as they were before the chain ran them in one pass over one table: each filter
// its own arrays, filtering a whole batch before the next filter sees it. A plain test oracle: the
// fused FilterChain must keep the same events and count the same drops.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evldt/filters/filter_chain.hpp"

namespace evldt::reference {

class EventFilter {
 public:
  virtual ~EventFilter() = default;
  /// The filter's name, which is also the reason its drops are counted under.
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// Writes to `out` the events of `in` that pass, in order; `out` may be `in` (filtered in place).
  /// Once `out` has held a batch as large, no allocation.
  virtual void filter(const EventBatch& in, EventBatch& out) = 0;
  /// Events this filter has removed so far.
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 protected:
  explicit EventFilter(SensorSize sensor) : sensor_(sensor) {}

  /// Copies the events of `in` for which pass(t, x, y, p) is true to `out` (which may be `in`), in
  /// order, and counts the others. A template, so that each filter's test inlines into the loop.
  template <typename Pass>
  void keep_if(const EventBatch& in, EventBatch& out, Pass&& pass) {
    const std::size_t size = in.size();
    if (&in != &out) out.truncate(size);  // room for every event: no allocation once warm
    std::size_t kept = 0;
    for (std::size_t i = 0; i < size; ++i) {
      const Timestamp t = in.t[i];
      const std::uint16_t x = in.x[i], y = in.y[i];
      const std::int8_t p = in.p[i];
      if (!pass(t, x, y, p)) continue;
      out.t[kept] = t;
      out.x[kept] = x;
      out.y[kept] = y;
      out.p[kept] = p;
      ++kept;
    }
    dropped_ += size - kept;
    out.truncate(kept);
  }
  [[nodiscard]] std::size_t pixel(std::uint16_t x, std::uint16_t y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(sensor_.width) + x;
  }
  [[nodiscard]] std::size_t pixels() const {
    return static_cast<std::size_t>(sensor_.width) * static_cast<std::size_t>(sensor_.height);
  }

  SensorSize sensor_;

 private:
  std::uint64_t dropped_ = 0;
};

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
  int stride_;  // the surface has a one-pixel border, so neighbours need no bounds checks
  // Per pixel, the low 32 bits of its last event's time (passed or not): half the memory traffic of
  // full times, and differences are exact for gaps under 71 minutes.
  std::vector<std::uint32_t> last_event_;
  bool started_ = false;
  static constexpr Timestamp kJudgeUs = 200'000;
  double min_uncorrelated_;  // per judging period
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
  std::vector<std::uint32_t> touched_;  // pixels with a count, to judge and reset
  std::vector<std::uint32_t> masked_list_;
  std::vector<std::uint32_t> still_masked_;  // scratch of judge_window
};

class AntiFlickerFilter final : public EventFilter {
 public:
  AntiFlickerFilter(SensorSize sensor, const AntiFlickerParams& params);
  [[nodiscard]] std::string_view name() const override { return "anti-flicker"; }
  void filter(const EventBatch& in, EventBatch& out) override;

 private:
  // Per pixel and polarity, 12 bytes. Times are the low 32 bits of us: differences are exact for
  // gaps under 71 minutes.
  struct Burst {
    std::uint32_t start = 0;  // time of the current burst's first event
    std::uint32_t last_event = 0;
    std::uint16_t period = 0;  // us, the locked or candidate period
    std::uint8_t streak = 0;   // consistent periods in a row
    std::uint8_t flags = 0;    // kSeen, kFlickerBurst
  };
  bool pass(Timestamp t, std::size_t pixel, bool on);
  [[nodiscard]] bool near(std::uint32_t a, std::uint32_t b) const;

  AntiFlickerParams params_;
  std::uint32_t min_period_, max_period_;
  std::vector<Burst> bursts_;  // [pixel * 2 + (on ? 1 : 0)]
};

/// The filters of `config.chain`, run one after another on each batch.
class FilterChain {
 public:
  FilterChain(const FilterConfig& config, SensorSize sensor);
  void filter(const EventBatch& in, EventBatch& out);
  [[nodiscard]] FilterCounts counts() const;
  [[nodiscard]] std::span<const std::uint32_t> masked_pixels() const;

 private:
  std::vector<std::unique_ptr<EventFilter>> filters_;
  const HotPixelFilter* hot_pixel_ = nullptr;
  std::uint64_t events_in_ = 0, passed_ = 0;
};

}  // namespace evldt::reference
