// Event Stream (.es, version 2; the Neuromorphic-Drivers / sepia format of Prophesee ATIS and DVS
// cameras): "Event Stream", three version bytes (major 2), a type byte (1 DVS, 2 ATIS), width and
// height as little-endian uint16, then events as time deltas in a byte, each followed by x and y
// (little-endian uint16; origin bottom left, mirrored here to evldt's top left):
//   DVS:  0xFF: t += 127; 0xFE: reset (nothing); else t += b >> 1, polarity b & 1, x, y.
//   ATIS: (b & 0xFC) == 0xFC: t += 63 * (b & 3) (0xFC itself resets); else t += b >> 2, [0] is a
//         threshold crossing (exposure measurement: skipped and counted), [1] polarity, x, y.
// Events off the sensor are left to the validator.

#include <array>
#include <cstring>

#include "evldt/events/event_decoder.hpp"

namespace evldt::detail {
namespace {

constexpr std::string_view kSignature = "Event Stream";
constexpr std::size_t kHeaderBytes = 20;  // signature, version, type, width, height

class EventStreamDecoder final : public EventDecoder {
 public:
  explicit EventStreamDecoder(std::string source) : source_(std::move(source)) {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    for (const std::uint8_t byte : chunk) {
      if (header_bytes_ < kHeaderBytes) {
        header_[header_bytes_++] = byte;
        if (header_bytes_ == kHeaderBytes) read_header();
      } else if (coordinates_ > 0) {
        coordinate_bytes_[4 - coordinates_--] = byte;
        if (coordinates_ == 0) emit(out);
      } else {
        event_start_ = offset_;
        on_time_byte(byte);
      }
      ++offset_;
    }
  }

  void finish(EventBatch&) override {
    if (header_bytes_ < kHeaderBytes)
      throw FormatError(source_, header_bytes_, "file ends inside the Event Stream header");
    if (coordinates_ > 0) throw FormatError(source_, event_start_, "file ends inside an event");
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return sensor_; }
  [[nodiscard]] DecodeCounts counts() const override { return counts_; }

 private:
  void read_header() {
    if (std::memcmp(header_.data(), kSignature.data(), kSignature.size()) != 0) {
      throw FormatError(source_, 0, "not an Event Stream file (no 'Event Stream' signature)");
    }
    if (header_[12] != 2)
      throw FormatError(source_, 12, "Event Stream version " + std::to_string(header_[12]) + ".x (evldt reads 2.x)");
    atis_ = header_[15] == 2;
    if (header_[15] != 1 && !atis_) {
      throw FormatError(source_, 15,
                        "Event Stream of type " + std::to_string(header_[15]) + " (evldt reads DVS 1 and ATIS 2)");
    }
    const SensorSize size{load_le16(header_.data() + 16), load_le16(header_.data() + 18)};
    if (!size.valid()) throw FormatError(source_, 16, size.range_error());
    sensor_ = size;
  }

  void on_time_byte(std::uint8_t byte) {
    if (!atis_) {
      if (byte == 0xFF) {
        t_ += 127;
      } else if (byte != 0xFE) {
        t_ += byte >> 1;
        polarity_ = (byte & 1) != 0;
        threshold_crossing_ = false;
        coordinates_ = 4;
      }
      return;
    }
    if ((byte & 0xFC) == 0xFC) {
      t_ += 63 * (byte & 3);
      return;
    }
    t_ += byte >> 2;
    threshold_crossing_ = (byte & 1) != 0;
    polarity_ = (byte & 2) != 0;
    coordinates_ = 4;
  }

  void emit(EventBatch::Appender& out) {
    if (threshold_crossing_) {
      ++counts_.skipped_words;
      return;
    }
    const std::uint16_t x = load_le16(coordinate_bytes_.data()), y = load_le16(coordinate_bytes_.data() + 2);
    // Mirrored only when on the sensor: the validator drops and counts the others.
    const auto top_down = y < sensor_->height ? static_cast<std::uint16_t>(sensor_->height - 1 - y) : y;
    out.push_back(t_, x, top_down, polarity_ ? std::int8_t{1} : std::int8_t{-1});
  }

  std::string source_;
  std::array<std::uint8_t, kHeaderBytes> header_{};
  std::size_t header_bytes_ = 0;
  std::optional<SensorSize> sensor_;
  bool atis_ = false;
  Timestamp t_ = 0;
  bool polarity_ = false;
  bool threshold_crossing_ = false;
  int coordinates_ = 0;  // bytes of x and y still to come
  std::array<std::uint8_t, 4> coordinate_bytes_{};
  std::uint64_t offset_ = 0, event_start_ = 0;
  DecodeCounts counts_;
};

}  // namespace

std::unique_ptr<EventDecoder> make_event_stream_decoder(std::string source_name) {
  return std::make_unique<EventStreamDecoder>(std::move(source_name));
}

}  // namespace evldt::detail
