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
  /// Removes from `batch` the events that do not pass, keeping the order of the rest.
  virtual void filter(EventBatch& batch) = 0;
  /// Events this filter has removed so far.
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 protected:
  explicit EventFilter(SensorSize sensor) : sensor_(sensor) {}

  /// Keeps the events i for which pass(t, x, y, p) is true, in order, and counts the others. A
  /// template, so that each filter's test inlines into the loop.
  template <typename Pass>
  void keep_if(EventBatch& batch, Pass&& pass) {
    std::size_t kept = 0;
    const std::size_t size = batch.size();
    for (std::size_t i = 0; i < size; ++i) {
      if (!pass(batch.t[i], batch.x[i], batch.y[i], batch.p[i])) continue;
      batch.t[kept] = batch.t[i];
      batch.x[kept] = batch.x[i];
      batch.y[kept] = batch.y[i];
      batch.p[kept] = batch.p[i];
      ++kept;
    }
    dropped_ += size - kept;
    batch.truncate(kept);
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
