// Prophesee RAW EVT 3.0: a '%' text header, then little-endian 16-bit words whose top 4 bits are the type.
// The format is stateful: words set y, a base x, or the time, and event words refer to that state.
//   EVT_ADDR_Y 0x0:    [10:0] y ([11] system type, ignored)
//   EVT_ADDR_X 0x2:    [11] polarity, [10:0] x; one event
//   VECT_BASE_X 0x3:   [11] polarity, [10:0] base x for the vectors that follow
//   VECT_12 0x4:       [11:0] one event at base x + i per set bit i, then base x += 12
//   VECT_8 0x5:        [7:0] likewise, then base x += 8
//   EVT_TIME_LOW 0x6:  [11:0] time bits 0..11
//   EVT_TIME_HIGH 0x8: [11:0] time bits 12..23
//   EXT_TRIGGER 0xA: counted. CONTINUED_4 0x7, OTHERS 0xE, CONTINUED_12 0xF: not CD events, skipped.
//   Every other type is reserved: skipped and counted, as the vendor SDK skips it (some IMX636
//   cameras insert 0x9999 padding words), so no word can stop a stream.
// Events before the first EVT_TIME_HIGH are dropped (their time is unknown), as Prophesee's decoder does;
// that is not an error.

#include <bit>

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_writer.hpp"

namespace evldt::detail {
namespace {

enum Evt3Type : std::uint16_t {
  kAddrY = 0x0,
  kAddrX = 0x2,
  kVectBaseX = 0x3,
  kVect12 = 0x4,
  kVect8 = 0x5,
  kTimeLow = 0x6,
  kContinued4 = 0x7,
  kTimeHigh = 0x8,
  kExtTrigger = 0xA,
  kOthers = 0xE,
  kContinued12 = 0xF,
};

constexpr int kTimeLowBits = 12;
constexpr int kTimeBits = 24;
constexpr std::uint16_t kTwelveBits = 0xFFF;
constexpr int kMaxCoordinate = 2047;  // 11 bits
// The 24-bit time base wraps every 2^24 us (16.8 s). A time high that goes back by half its range or more
// is a wrap; the encoder never steps forward by that much, so it cannot be confused.
constexpr std::uint16_t kTimeHighHalfRange = 1u << (kTimeBits - kTimeLowBits - 1);
constexpr Timestamp kMaxTimeHighStep = kTimeHighHalfRange - 1;

std::int8_t polarity_of(std::uint16_t word) { return (word & 0x800) != 0 ? std::int8_t{1} : std::int8_t{-1}; }

class Evt3Decoder final : public EventDecoder {
 public:
  Evt3Decoder(std::string source, RawFraming framing)
      : source_(std::move(source)), bare_words_(framing == RawFraming::BareWords) {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    if (!bare_words_ && !header_.complete()) {
      if (!header_.take(chunk, source_)) return;
      check_encoding();
      words_.set_offset(header_.size());
    }
    // The state as a local, so that it stays in registers: the event stores (int8 polarity) may
    // alias any member, which would be reloaded every word. No word throws.
    State state = state_;
    EventBatch::Appender out(batch);
    words_.feed(chunk, [&](const std::uint8_t* bytes, std::uint64_t) { decode_word(load_le16(bytes), state, out); });
    state_ = state;
  }

  void finish(EventBatch& /*out*/) override {
    if (!bare_words_) header_.finish(source_);
    if (words_.carried() > 0)
      throw FormatError(source_, words_.offset(), "file ends inside an EVT 3.0 word (1 of 2 bytes)");
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return header_.geometry(); }
  [[nodiscard]] DecodeCounts counts() const override { return state_.counts; }

 private:
  struct State {
    DecodeCounts counts;
    std::uint16_t y = 0;
    std::uint16_t base_x = 0;
    std::int8_t vector_polarity = 1;
    bool has_time = false;
    std::uint16_t time_high = 0;
    std::uint16_t time_low = 0;
    Timestamp wraps = 0;
    Timestamp time_high_us = 0;  // (wraps << 24) + (time_high << 12): the time but its low bits

    [[nodiscard]] Timestamp time_us() const { return time_high_us + time_low; }
  };

  void check_encoding() const {
    const auto encoding = header_.encoding();
    if (encoding && raw_format_from_encoding(*encoding) != EventFormat::Evt3) {
      throw FormatError(source_, 0, "the header says the data is " + *encoding + ", not EVT3");
    }
  }

  static void decode_word(std::uint16_t word, State& s, EventBatch::Appender& out) {
    // EVT_ADDR_X and EVT_ADDR_Y, most words of most streams, by conditional branches before the
    // jump table: the indirect jump mispredicts more often where they alternate irregularly.
    const unsigned type = word >> 12;
    if (type == kAddrX) {
      if (s.has_time) out.push_back(s.time_us(), static_cast<std::uint16_t>(word & 0x7FF), s.y, polarity_of(word));
      return;
    }
    if (type == kAddrY) {
      s.y = word & 0x7FF;
      return;
    }
    switch (type) {
      case kVectBaseX:
        s.base_x = word & 0x7FF;
        s.vector_polarity = polarity_of(word);
        return;
      case kVect12:
        emit_vector(word & kTwelveBits, 12, s, out);
        return;
      case kVect8:
        emit_vector(word & 0xFF, 8, s, out);
        return;
      case kTimeLow:
        s.time_low = word & kTwelveBits;
        return;
      case kTimeHigh: {
        const std::uint16_t time_high = word & kTwelveBits;
        if (s.has_time && s.time_high >= time_high + kTimeHighHalfRange) s.wraps += 1;
        // The TIME_LOW that belongs to a new time high follows it; until then its low bits are 0.
        if (!s.has_time || time_high != s.time_high) s.time_low = 0;
        s.time_high = time_high;
        s.has_time = true;
        s.time_high_us = (s.wraps << kTimeBits) + (static_cast<Timestamp>(time_high) << kTimeLowBits);
        return;
      }
      case kExtTrigger:
        ++s.counts.trigger_events;
        return;
      case kContinued4:
      case kOthers:
      case kContinued12:
        return;
      default:
        ++s.counts.skipped_words;
        return;  // reserved, e.g. the 0x9999 padding of some IMX636 cameras
    }
  }

  static void emit_vector(std::uint32_t valid_bits, std::uint16_t length, State& s, EventBatch::Appender& out) {
    if (s.has_time) {
      const Timestamp t = s.time_us();
      for (; valid_bits != 0; valid_bits &= valid_bits - 1) {
        out.push_back(t, static_cast<std::uint16_t>(s.base_x + std::countr_zero(valid_bits)), s.y, s.vector_polarity);
      }
    }
    s.base_x = static_cast<std::uint16_t>(s.base_x + length);
  }

  std::string source_;
  bool bare_words_;
  TextHeader header_;
  WordSplitter<2> words_;
  State state_;
};

/// A simple valid encoding: TIME_HIGH/TIME_LOW when they change, EVT_ADDR_Y when y changes, one
/// EVT_ADDR_X per event (no vectors).
class Evt3Encoder final : public EventEncoder {
 public:
  explicit Evt3Encoder(SensorSize sensor) : sensor_(sensor) {}

  void write_header(std::vector<std::uint8_t>& out) const override { write_raw_header("EVT3", sensor_, out); }

  void encode(const EventBatch& batch, std::vector<std::uint8_t>& out) override {
    check_encodable(batch, last_time_, kMaxCoordinate, "EVT 3.0");
    for (std::size_t i = 0; i < batch.size(); ++i) {
      const Timestamp t = batch.t[i];
      const Timestamp time_high = t >> kTimeLowBits;
      const auto time_low = static_cast<std::uint16_t>(t & kTwelveBits);
      if (!has_time_ || time_high != time_high_) {
        // Long gaps go in steps the decoder can follow across the 2^24 us wrap.
        while (time_high - time_high_ > kMaxTimeHighStep) write_word(kTimeHigh, time_high_ + kMaxTimeHighStep, out);
        write_word(kTimeHigh, time_high, out);
        write_word(kTimeLow, time_low, out);
        has_time_ = true;
        time_high_ = time_high;
        time_low_ = time_low;
      } else if (time_low != time_low_) {
        write_word(kTimeLow, time_low, out);
        time_low_ = time_low;
      }
      if (!has_y_ || batch.y[i] != y_) {
        write_word(kAddrY, batch.y[i], out);
        has_y_ = true;
        y_ = batch.y[i];
      }
      write_word(kAddrX, batch.x[i] | (batch.p[i] > 0 ? 0x800 : 0), out);
    }
    if (!batch.empty()) last_time_ = batch.t.back();
  }

 private:
  void write_word(Evt3Type type, Timestamp payload, std::vector<std::uint8_t>& out) {
    if (type == kTimeHigh) time_high_ = payload;
    append_le16(static_cast<std::uint16_t>((type << 12) | (payload & kTwelveBits)), out);
  }

  SensorSize sensor_;
  Timestamp last_time_ = 0;
  bool has_time_ = false;
  Timestamp time_high_ = 0;  // the decoder's wrap detection starts from 0 too
  std::uint16_t time_low_ = 0;
  bool has_y_ = false;
  std::uint16_t y_ = 0;
};

}  // namespace

std::unique_ptr<EventDecoder> make_evt3_decoder(std::string source_name, RawFraming framing) {
  return std::make_unique<Evt3Decoder>(std::move(source_name), framing);
}

std::unique_ptr<EventEncoder> make_evt3_encoder(SensorSize sensor) {
  if (!sensor.valid() || sensor.width > kMaxCoordinate + 1 || sensor.height > kMaxCoordinate + 1) {
    throw std::invalid_argument("EVT 3.0 describes sensors up to 2048x2048, not " + std::to_string(sensor.width) + "x" +
                                std::to_string(sensor.height));
  }
  return std::make_unique<Evt3Encoder>(sensor);
}

}  // namespace evldt::detail
