#pragma once
// What EVT 2.0 and EVT 2.1 share: the word types and the time. TIME_HIGH words carry time bits
// 6..33 (28 bits, so the time wraps every 2^34 us, 4.8 h); event words carry the 6 low bits.

#include <cstdint>

#include "evldt/events/event.hpp"

namespace evldt::detail::evt2 {

enum Type : std::uint32_t {
  kCdOff = 0x0,  ///< EVT 2.1: a vector of OFF events
  kCdOn = 0x1,   ///< EVT 2.1: a vector of ON events
  kTimeHigh = 0x8,
  kExtTrigger = 0xA,
  kOthers = 0xE,
  kContinued = 0xF,
};

constexpr int kTimeLowBits = 6;
constexpr int kTimeHighBits = 28;
constexpr std::uint32_t kTimeHighMask = (1u << kTimeHighBits) - 1;
constexpr int kMaxCoordinate = 2047;  // 11 bits
// A time high that goes back by half its range or more is a wrap; the encoders never step forward
// by half the range or more, so it cannot be confused.
constexpr std::uint32_t kTimeHighHalfRange = 1u << (kTimeHighBits - 1);
constexpr Timestamp kMaxTimeHighStep = kTimeHighHalfRange - 1;

/// Follows the TIME_HIGH words of a stream across their wrap.
class TimeHighClock {
 public:
  void on_time_high(std::uint32_t time_high) {
    time_high &= kTimeHighMask;
    if (known_ && last_ >= time_high + kTimeHighHalfRange) wraps_ += 1;
    last_ = time_high;
    known_ = true;
    base_us_ = ((wraps_ << kTimeHighBits) + time_high) << kTimeLowBits;
  }
  /// Whether a TIME_HIGH has been seen.
  [[nodiscard]] bool known() const { return known_; }
  /// The time of the last TIME_HIGH in us (0 before the first), to which events add their low bits.
  [[nodiscard]] Timestamp base_us() const { return base_us_; }

 private:
  bool known_ = false;
  std::uint32_t last_ = 0;
  Timestamp wraps_ = 0;
  Timestamp base_us_ = 0;
};

/// The encoders' side: the TIME_HIGH words to write before an event so that a TimeHighClock follows.
class TimeHighWriter {
 public:
  /// Calls write(time_high) for each TIME_HIGH due before an event at `t`: long gaps in steps the
  /// wrap detection can follow, and always one before the first event (other decoders wait for it).
  template <typename Write>
  void before_event(Timestamp t, Write&& write) {
    const Timestamp time_high = t >> kTimeLowBits;
    while (time_high - time_high_ > kMaxTimeHighStep) emit(time_high_ + kMaxTimeHighStep, write);
    if (!wrote_ || time_high != time_high_) emit(time_high, write);
  }

 private:
  template <typename Write>
  void emit(Timestamp time_high, Write& write) {
    time_high_ = time_high;
    wrote_ = true;
    write(static_cast<std::uint32_t>(time_high) & kTimeHighMask);
  }

  Timestamp time_high_ = 0;  // as the decoder sees it before the first TIME_HIGH
  bool wrote_ = false;
};

}  // namespace evldt::detail::evt2
