// Prophesee RAW EVT 2.1: a '%' text header, then 64-bit words. As a 64-bit value:
//   EVT_NEG 0x0 / EVT_POS 0x1: [63:60] type, [59:54] time bits 0..5, [53:43] x, [42:32] y,
//                              [31:0] valid mask: one event at (x + i, y) per set bit i
//   EVT_TIME_HIGH 0x8:         [59:32] time bits 6..33
//   EXT_TRIGGER 0xA: counted.  OTHERS 0xE, CONTINUED 0xF: skipped. Other types: reserved, skipped and counted.
// The two 32-bit halves are stored in one of two orders: "little" (the whole word little-endian,
// so the mask comes first; GenX320) or "legacy" (the half with the type first; IMX636). The header
// says which ("% format EVT21;endianness=..." or "% endianness"); without it, a Prophesee camera
// older than the SAPHIR system id (0x37) writes legacy, as the vendor SDK assumes.
// Events before the first TIME_HIGH have no known time and are dropped, as the vendor SDK does.

#include <bit>

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_writer.hpp"
#include "evt2_time.hpp"

namespace evldt::detail {
namespace {

using namespace evt2;

constexpr int kSaphirSystemId = 0x37;

class Evt21Decoder final : public EventDecoder {
 public:
  explicit Evt21Decoder(std::string source) : source_(std::move(source)) {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    if (!header_.complete()) {
      if (!header_.take(chunk, source_)) return;
      read_header();
      words_.set_offset(header_.size());
    }
    words_.feed(chunk, [&](const std::uint8_t* bytes, std::uint64_t) {
      const std::uint64_t first = load_le32(bytes), second = load_le32(bytes + 4);
      decode_word(legacy_ ? (first << 32 | second) : (second << 32 | first), out);
    });
  }

  void finish(EventBatch&) override {
    header_.finish(source_);
    if (words_.carried() > 0) {
      throw FormatError(source_, words_.offset(),
                        "file ends inside an EVT 2.1 word (" + std::to_string(words_.carried()) + " of 8 bytes)");
    }
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return header_.geometry(); }
  [[nodiscard]] DecodeCounts counts() const override { return counts_; }

 private:
  void read_header() {
    const auto encoding = header_.encoding();
    if (encoding && raw_format_from_encoding(*encoding) != EventFormat::Evt21) {
      throw FormatError(source_, 0, "the header says the data is " + *encoding + ", not EVT21");
    }
    if (const auto order = header_.option("endianness")) {
      if (*order != "legacy" && *order != "little")
        throw FormatError(source_, 0, "unknown EVT 2.1 endianness '" + *order + "'");
      legacy_ = *order == "legacy";
    } else {
      const auto system = header_.system_id();
      legacy_ = system && *system < kSaphirSystemId;
    }
  }

  void decode_word(std::uint64_t word, EventBatch::Appender& out) {
    switch (word >> 60) {
      case kCdOff:
      case kCdOn: {
        if (!clock_.known()) return;
        const Timestamp t = clock_.base_us() + static_cast<Timestamp>((word >> 54) & 0x3F);
        const auto x = static_cast<std::uint32_t>((word >> 43) & 0x7FF);
        const auto y = static_cast<std::uint16_t>((word >> 32) & 0x7FF);
        const std::int8_t polarity = (word >> 60) == kCdOn ? std::int8_t{1} : std::int8_t{-1};
        for (auto mask = static_cast<std::uint32_t>(word); mask != 0; mask &= mask - 1) {
          out.push_back(t, static_cast<std::uint16_t>(x + static_cast<std::uint32_t>(std::countr_zero(mask))), y,
                        polarity);
        }
        return;
      }
      case kTimeHigh:
        clock_.on_time_high(static_cast<std::uint32_t>(word >> 32));
        return;
      case kExtTrigger:
        ++counts_.trigger_events;
        return;
      case kOthers:
      case kContinued:
        return;
      default:
        ++counts_.skipped_words;
        return;
    }
  }

  std::string source_;
  TextHeader header_;
  WordSplitter<8> words_;
  bool legacy_ = false;
  TimeHighClock clock_;
  DecodeCounts counts_;
};

/// One word per event (a mask of one bit), TIME_HIGH when it changes; little byte order.
class Evt21Encoder final : public EventEncoder {
 public:
  explicit Evt21Encoder(SensorSize sensor) : sensor_(sensor) {}

  void write_header(std::vector<std::uint8_t>& out) const override { write_raw_header("EVT21", sensor_, out); }

  void encode(const EventBatch& batch, std::vector<std::uint8_t>& out) override {
    check_encodable(batch, last_time_, kMaxCoordinate, "EVT 2.1");
    for (std::size_t i = 0; i < batch.size(); ++i) {
      const Timestamp t = batch.t[i];
      time_high_.before_event(t, [&](std::uint32_t time_high) {
        write_word(std::uint64_t{kTimeHigh} << 60 | std::uint64_t{time_high} << 32, out);
      });
      const std::uint64_t type = batch.p[i] > 0 ? kCdOn : kCdOff;
      write_word(type << 60 | static_cast<std::uint64_t>(t & 0x3F) << 54 | std::uint64_t{batch.x[i]} << 43 |
                     std::uint64_t{batch.y[i]} << 32 | 1u,
                 out);
    }
    if (!batch.empty()) last_time_ = batch.t.back();
  }

 private:
  static void write_word(std::uint64_t word, std::vector<std::uint8_t>& out) {
    append_le32(static_cast<std::uint32_t>(word), out);
    append_le32(static_cast<std::uint32_t>(word >> 32), out);
  }

  SensorSize sensor_;
  Timestamp last_time_ = 0;
  TimeHighWriter time_high_;
};

}  // namespace

std::unique_ptr<EventDecoder> make_evt21_decoder(std::string source_name) {
  return std::make_unique<Evt21Decoder>(std::move(source_name));
}

std::unique_ptr<EventEncoder> make_evt21_encoder(SensorSize sensor) {
  if (!sensor.valid() || sensor.width > kMaxCoordinate + 1 || sensor.height > kMaxCoordinate + 1) {
    throw std::invalid_argument("EVT 2.1 describes sensors up to 2048x2048, not " + std::to_string(sensor.width) + "x" +
                                std::to_string(sensor.height));
  }
  return std::make_unique<Evt21Encoder>(sensor);
}

}  // namespace evldt::detail
