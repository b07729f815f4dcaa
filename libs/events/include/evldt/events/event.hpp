#pragma once
// Events and event batches: the unit of data every part of evldt exchanges.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace evldt {

/// Event time in microseconds.
using Timestamp = std::int64_t;

/// Largest sensor side evldt works with. Above every event camera made (1280x960 at most today);
/// the bound keeps a forged size in a file header or a message from claiming unbounded memory
/// (the lattice of a 4096x4096 sensor takes about 35 MB).
inline constexpr int kMaxSensorSide = 4096;

struct SensorSize {
  int width = 0;
  int height = 0;

  [[nodiscard]] bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
  /// Both sides in 1..kMaxSensorSide.
  [[nodiscard]] bool valid() const {
    return width > 0 && height > 0 && width <= kMaxSensorSide && height <= kMaxSensorSide;
  }
  /// The error message for a size valid() refuses.
  [[nodiscard]] std::string range_error() const {
    const std::string side = std::to_string(kMaxSensorSide);
    return "sensor size " + std::to_string(width) + "x" + std::to_string(height) + " is not in 1x1.." + side + "x" + side;
  }
  friend bool operator==(const SensorSize&, const SensorSize&) = default;
};

/// One change-detection event: time, pixel, polarity (+1 brighter, -1 darker).
struct Event {
  Timestamp t = 0;
  std::uint16_t x = 0;
  std::uint16_t y = 0;
  std::int8_t p = 1;
  friend bool operator==(const Event&, const Event&) = default;
};

/// A run of events in time order, stored as structure-of-arrays: storage reads only x and y, and
/// the LCM message carries the same typed arrays (evldt-bench measures both layouts).
class EventBatch {
 public:
  std::vector<Timestamp> t;
  std::vector<std::uint16_t> x;
  std::vector<std::uint16_t> y;
  std::vector<std::int8_t> p;

  [[nodiscard]] std::size_t size() const { return t.size(); }
  [[nodiscard]] bool empty() const { return t.empty(); }

  void reserve(std::size_t n) {
    t.reserve(n);
    x.reserve(n);
    y.reserve(n);
    p.reserve(n);
  }
  void clear() {
    t.clear();
    x.clear();
    y.clear();
    p.clear();
  }
  void push_back(const Event& e) { push_back(e.t, e.x, e.y, e.p); }
  void push_back(Timestamp time, std::uint16_t px, std::uint16_t py, std::int8_t polarity) {
    t.push_back(time);
    x.push_back(px);
    y.push_back(py);
    p.push_back(polarity);
  }
  /// Appends events [begin, end) of `from` (another batch).
  void append(const EventBatch& from, std::size_t begin, std::size_t end) {
    const auto first = static_cast<std::ptrdiff_t>(begin), last = static_cast<std::ptrdiff_t>(end);
    t.insert(t.end(), from.t.begin() + first, from.t.begin() + last);
    x.insert(x.end(), from.x.begin() + first, from.x.begin() + last);
    y.insert(y.end(), from.y.begin() + first, from.y.begin() + last);
    p.insert(p.end(), from.p.begin() + first, from.p.begin() + last);
  }
  /// Keeps the first n events (or grows to n, the new ones zero).
  void truncate(std::size_t n) {
    t.resize(n);
    x.resize(n);
    y.resize(n);
    p.resize(n);
  }
  [[nodiscard]] Event operator[](std::size_t i) const { return {t[i], x[i], y[i], p[i]}; }
};

}  // namespace evldt
