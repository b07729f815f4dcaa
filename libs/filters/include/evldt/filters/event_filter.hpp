#pragma once
// Noise filters that run before the lattice, each a small class behind one interface and chained in
// order (filter_chain.hpp). A filter sees on-sensor events in time order (an EventValidator runs
// first), keeps per-pixel state in arrays sized to the sensor and allocated once, and costs O(1) per
// event.

#include <cstdint>
#include <string_view>

#include "evldt/events/event.hpp"

namespace evldt {

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

}  // namespace evldt
