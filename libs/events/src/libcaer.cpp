// The encodings event_camera_msgs/EventPacket uses for iniVation cameras (ros-event-camera's
// libcaer_driver and event_camera_codecs). Both are packets of a container (a ROS bag); each packet
// carries a time base in ns.
//
// "libcaer": 8-byte little-endian records, uint32 data then int32 time (us):
//   data [0] valid, [1] polarity (1 ON), [16:2] y, [31:17] x.
//   t = time_base + time * 1000 ns; the 31-bit time wraps, so within a packet a time that goes back
//   adds 2^31 us (the time base of the next packet carries the wrap). Invalid records are skipped
//   and counted.
// "libcaer_cmp": 16-bit little-endian words, [15:12] code, [11:0] payload, column by column:
//   0 TIME_HIGH: time bits 12..23     1 TIME_LOW: time bits 0..11
//   2 ADDR_X: [10:0] x of what follows 3 ADDR_Y: [11] polarity, [10:0] y: one event at (x, y)
//   4 VECT_BASE_Y: [11] polarity, [10:0] base y   5 VECT_8: [7:0] one event at base y + i per set bit i, base y += 8
//   t = time_base + ((TIME_HIGH << 12) | TIME_LOW) us; the time starts at 0 in every packet (x, y
//   and polarity carry over). Other codes are skipped and counted.

#include <bit>

#include "evldt/events/event_decoder.hpp"

namespace evldt::detail {
namespace {

class LibcaerDecoder final : public EventDecoder {
 public:
  explicit LibcaerDecoder(std::string source) : source_(std::move(source)) {}
  void start_packet(std::int64_t time_base_ns) override {
    base_us_ = floor_ns_to_us(time_base_ns);
    wrap_us_ = 0;
    last_time_ = 0;
  }

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    records_.feed(chunk, [&](const std::uint8_t* record, std::uint64_t) {
      const std::uint32_t data = load_le32(record);
      const auto time = static_cast<std::int32_t>(load_le32(record + 4));
      if (time < last_time_) wrap_us_ += Timestamp{1} << 31;
      last_time_ = time;
      if ((data & 1u) == 0) {
        ++counts_.skipped_words;
        return;
      }
      out.push_back(base_us_ + wrap_us_ + time, static_cast<std::uint16_t>(data >> 17),
                    static_cast<std::uint16_t>((data >> 2) & 0x7FFF),
                    (data & 2u) != 0 ? std::int8_t{1} : std::int8_t{-1});
    });
  }

  void finish(EventBatch&) override {
    if (records_.carried() > 0)
      throw FormatError(source_, records_.offset(), "libcaer data ends inside an 8-byte event");
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }
  [[nodiscard]] DecodeCounts counts() const override { return counts_; }

 private:
  std::string source_;
  WordSplitter<8> records_;
  Timestamp base_us_ = 0;
  Timestamp wrap_us_ = 0;
  std::int32_t last_time_ = 0;
  DecodeCounts counts_;
};

class LibcaerCompressedDecoder final : public EventDecoder {
 public:
  explicit LibcaerCompressedDecoder(std::string source) : source_(std::move(source)) {}
  void start_packet(std::int64_t time_base_ns) override {
    base_us_ = floor_ns_to_us(time_base_ns);
    time_high_ = 0;
    time_low_ = 0;
  }

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    words_.feed(chunk, [&](const std::uint8_t* bytes, std::uint64_t) {
      const std::uint16_t word = load_le16(bytes);
      const std::uint16_t payload = word & 0xFFF;
      switch (word >> 12) {
        case 0:
          time_high_ = payload;
          return;
        case 1:
          time_low_ = payload;
          return;
        case 2:
          x_ = payload & 0x7FF;
          return;
        case 3:
          out.push_back(time_us(), x_, payload & 0x7FF, polarity_of(payload));
          return;
        case 4:
          base_y_ = payload & 0x7FF;
          polarity_ = polarity_of(payload);
          return;
        case 5: {
          const Timestamp t = time_us();
          for (std::uint32_t bits = payload & 0xFFu; bits != 0; bits &= bits - 1) {
            out.push_back(t, x_, static_cast<std::uint16_t>(base_y_ + std::countr_zero(bits)), polarity_);
          }
          base_y_ = static_cast<std::uint16_t>(base_y_ + 8);
          return;
        }
        default:
          ++counts_.skipped_words;
          return;
      }
    });
  }

  void finish(EventBatch&) override {
    if (words_.carried() > 0) throw FormatError(source_, words_.offset(), "libcaer_cmp data ends inside a 16-bit word");
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }
  [[nodiscard]] DecodeCounts counts() const override { return counts_; }

 private:
  static std::int8_t polarity_of(std::uint16_t payload) {
    return (payload & 0x800) != 0 ? std::int8_t{1} : std::int8_t{-1};
  }
  [[nodiscard]] Timestamp time_us() const { return base_us_ + ((Timestamp{time_high_} << 12) | time_low_); }

  std::string source_;
  WordSplitter<2> words_;
  Timestamp base_us_ = 0;
  std::uint16_t time_high_ = 0, time_low_ = 0;
  std::uint16_t x_ = 0, base_y_ = 0;
  std::int8_t polarity_ = 1;
  DecodeCounts counts_;
};

}  // namespace

std::unique_ptr<EventDecoder> make_libcaer_decoder(std::string source_name) {
  return std::make_unique<LibcaerDecoder>(std::move(source_name));
}
std::unique_ptr<EventDecoder> make_libcaer_compressed_decoder(std::string source_name) {
  return std::make_unique<LibcaerCompressedDecoder>(std::move(source_name));
}

}  // namespace evldt::detail
