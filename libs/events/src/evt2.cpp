// Prophesee RAW EVT 2.0: a '%' text header, then little-endian 32-bit words whose top 4 bits are the type.
//   CD_OFF 0x0 / CD_ON 0x1: [27:22] time bits 0..5, [21:11] x, [10:0] y
//   EVT_TIME_HIGH 0x8:      [27:0] time bits 6..33
//   EXT_TRIGGER 0xA: counted. OTHERS 0xE, CONTINUED 0xF: not CD events, skipped.
//   Every other type is reserved: skipped and counted, as the vendor SDK skips it.

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_writer.hpp"
#include "evt2_time.hpp"

namespace evldt::detail {
namespace {

using namespace evt2;

class Evt2Decoder final : public EventDecoder {
 public:
  Evt2Decoder(std::string source, RawFraming framing)
      : source_(std::move(source)), bare_words_(framing == RawFraming::BareWords) {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    if (!bare_words_ && !header_.complete()) {
      if (!header_.take(chunk, source_)) return;
      check_encoding();
      words_.set_offset(header_.size());
    }
    words_.feed(chunk, [&](const std::uint8_t* bytes, std::uint64_t) { decode_word(load_le32(bytes), out); });
  }

  void finish(EventBatch& /*out*/) override {
    if (!bare_words_) header_.finish(source_);
    if (words_.carried() > 0) {
      throw FormatError(source_, words_.offset(),
                        "file ends inside an EVT 2.0 word (" + std::to_string(words_.carried()) + " of 4 bytes)");
    }
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return header_.geometry(); }
  [[nodiscard]] DecodeCounts counts() const override { return counts_; }

 private:
  void check_encoding() const {
    const auto encoding = header_.encoding();
    if (encoding && raw_format_from_encoding(*encoding) != EventFormat::Evt2) {
      throw FormatError(source_, 0, "the header says the data is " + *encoding + ", not EVT2");
    }
  }

  void decode_word(std::uint32_t word, EventBatch::Appender& out) {
    switch (word >> 28) {
      case kCdOff:
      case kCdOn:
        out.push_back(clock_.base_us() + ((word >> 22) & 0x3F), static_cast<std::uint16_t>((word >> 11) & 0x7FF),
                      static_cast<std::uint16_t>(word & 0x7FF),
                      (word >> 28) == kCdOn ? std::int8_t{1} : std::int8_t{-1});
        return;
      case kTimeHigh:
        clock_.on_time_high(word);
        return;
      case kExtTrigger:
        ++counts_.trigger_events;
        return;
      case kOthers:
      case kContinued:
        return;
      default:
        ++counts_.skipped_words;
        return;  // reserved: skipped as the vendor SDK does
    }
  }

  std::string source_;
  bool bare_words_;
  TextHeader header_;
  DecodeCounts counts_;
  WordSplitter<4> words_;
  TimeHighClock clock_;  // before the first TIME_HIGH the time high is 0
};

class Evt2Encoder final : public EventEncoder {
 public:
  explicit Evt2Encoder(SensorSize sensor) : sensor_(sensor) {}

  void write_header(std::vector<std::uint8_t>& out) const override { write_raw_header("EVT2", sensor_, out); }

  void encode(const EventBatch& batch, std::vector<std::uint8_t>& out) override {
    check_encodable(batch, last_time_, kMaxCoordinate, "EVT 2.0");
    for (std::size_t i = 0; i < batch.size(); ++i) {
      const Timestamp t = batch.t[i];
      time_high_.before_event(
          t, [&](std::uint32_t time_high) { append_le32(std::uint32_t{kTimeHigh} << 28 | time_high, out); });
      const std::uint32_t type = batch.p[i] > 0 ? kCdOn : kCdOff;
      append_le32((type << 28) | (static_cast<std::uint32_t>(t & 0x3F) << 22) |
                      (static_cast<std::uint32_t>(batch.x[i]) << 11) | batch.y[i],
                  out);
    }
    if (!batch.empty()) last_time_ = batch.t.back();
  }

 private:
  SensorSize sensor_;
  Timestamp last_time_ = 0;
  TimeHighWriter time_high_;
};

}  // namespace

std::unique_ptr<EventDecoder> make_evt2_decoder(std::string source_name, RawFraming framing) {
  return std::make_unique<Evt2Decoder>(std::move(source_name), framing);
}

std::unique_ptr<EventEncoder> make_evt2_encoder(SensorSize sensor) {
  if (!sensor.valid() || sensor.width > kMaxCoordinate + 1 || sensor.height > kMaxCoordinate + 1) {
    throw std::invalid_argument("EVT 2.0 describes sensors up to 2048x2048, not " + std::to_string(sensor.width) + "x" +
                                std::to_string(sensor.height));
  }
  return std::make_unique<Evt2Encoder>(sensor);
}

}  // namespace evldt::detail
