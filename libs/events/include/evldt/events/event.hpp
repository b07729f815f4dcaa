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
    return "sensor size " + std::to_string(width) + "x" + std::to_string(height) + " is not in 1x1.." + side + "x" +
           side;
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
  /// Capacity for n events, its memory already written: the first writes to fresh memory fault its
  /// pages in (on a virtual machine about 1.5 ms a megabyte), which a service does at start, not on
  /// its first batches.
  void reserve_touched(std::size_t n) {
    truncate(n);
    clear();
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

  class Appender;
};

/// Appends events to a batch faster than EventBatch::push_back, for decoders that emit event by
/// event: the columns grow a block at a time and each event is four plain stores, with no
/// per-column capacity check. While an appender is alive the columns may hold up to a block of
/// zeroed events beyond the ones appended, so the batch must not be used otherwise; the
/// destructor (also when an exception unwinds, e.g. a decoder's FormatError) trims the columns to
/// the events appended, so the batch then holds exactly what push_back would have left.
/// Keep it a local of the decoding function: its fields then stay in registers.
class EventBatch::Appender {
 public:
  explicit Appender(EventBatch& batch) : batch_(batch), size_(batch.size()), columns_(columns_of(batch)) {}
  ~Appender() { batch_.truncate(size_); }
  Appender(const Appender&) = delete;
  Appender& operator=(const Appender&) = delete;

  void push_back(Timestamp time, std::uint16_t px, std::uint16_t py, std::int8_t polarity) {
    if (size_ == columns_.room) [[unlikely]]
      columns_ = grow(batch_, size_);
    columns_.t[size_] = time;
    columns_.x[size_] = px;
    columns_.y[size_] = py;
    columns_.p[size_] = polarity;
    ++size_;
  }
  void push_back(const Event& e) { push_back(e.t, e.x, e.y, e.p); }
  /// Events in the batch so far (those it held before plus those appended).
  [[nodiscard]] std::size_t size() const { return size_; }

 private:
  struct Columns {
    Timestamp* t;
    std::uint16_t* x;
    std::uint16_t* y;
    std::int8_t* p;
    std::size_t room;  // events the columns hold now
  };
  // Small enough that the zeroing of a new block stays in L1 for the stores that overwrite it.
  static constexpr std::size_t kBlock = 1024;

  static Columns columns_of(EventBatch& batch) {
    return {batch.t.data(), batch.x.data(), batch.y.data(), batch.p.data(), batch.size()};
  }
  // Static and by value, so that the appender's own address never escapes (the int8 stores could
  // otherwise alias its fields, which would then be reloaded every event).
  [[gnu::noinline]] static Columns grow(EventBatch& batch, std::size_t size) {
    batch.truncate(size + kBlock);  // resize: geometric reallocation when the capacity runs out
    return columns_of(batch);
  }

  EventBatch& batch_;
  std::size_t size_;
  Columns columns_;
};

}  // namespace evldt
