// Prophesee .dat: a '%' text header ("% Width 640", "% Height 480", "% Version 2", ...), then two bytes,
// event type (0x0C CD events) and event size (8), then 8-byte little-endian records:
//   uint32 t (us), uint32 data: x = [13:0], y = [27:14], polarity = [31:28] (0 OFF, else ON).
// t is 32 bits and wraps every 2^32 us (71.6 min); a time that goes back by half that range or more is
// taken as a wrap, so consecutive events (and the first from 0) must be less than 2^31 us apart.

#include <cstdio>
#include <limits>

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_writer.hpp"

namespace evldt::detail {
namespace {

constexpr std::uint8_t kCdEventType = 0x0C;
constexpr std::uint8_t kEvent2dType = 0x00;  // the generic 2D event: same record layout
constexpr std::uint8_t kRecordBytes = 8;
constexpr int kMaxCoordinate = 0x3FFF;  // 14 bits
constexpr std::uint32_t kTimeHalfRange = 1u << 31;
constexpr Timestamp kTimeRange = Timestamp{1} << 32;

class DatDecoder final : public EventDecoder {
 public:
  explicit DatDecoder(std::string source) : source_(std::move(source)) {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    if (!header_.complete()) {
      if (!header_.take(chunk, source_)) return;
    }
    while (type_and_size_read_ < 2 && !chunk.empty()) {
      read_type_or_size(chunk.front());
      chunk = chunk.subspan(1);
    }
    if (type_and_size_read_ < 2) return;
    records_.feed(chunk, [&](const std::uint8_t* record, std::uint64_t /*offset*/) {
      decode_record(load_le32(record), load_le32(record + 4), out);
    });
  }

  void finish(EventBatch& /*out*/) override {
    header_.finish(source_);
    if (type_and_size_read_ < 2) {
      throw FormatError(source_, header_.size() + type_and_size_read_,
                        "file ends before the event type and size bytes");
    }
    if (records_.carried() > 0) {
      throw FormatError(source_, records_.offset(),
                        "file ends inside a dat record (" + std::to_string(records_.carried()) + " of 8 bytes)");
    }
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return header_.geometry(); }

 private:
  void read_type_or_size(std::uint8_t byte) {
    const std::uint64_t offset = header_.size() + type_and_size_read_;
    char reason[96];
    if (type_and_size_read_ == 0 && byte != kCdEventType && byte != kEvent2dType) {
      std::snprintf(reason, sizeof(reason), "event type 0x%02X is not CD events (0x0C)", byte);
      throw FormatError(source_, offset, reason);
    }
    if (type_and_size_read_ == 1 && byte != kRecordBytes) {
      std::snprintf(reason, sizeof(reason), "event size %u bytes, expected 8", static_cast<unsigned>(byte));
      throw FormatError(source_, offset, reason);
    }
    ++type_and_size_read_;
    if (type_and_size_read_ == 2) records_.set_offset(offset + 1);
  }

  void decode_record(std::uint32_t time, std::uint32_t data, EventBatch::Appender& out) {
    if (last_time_ >= time + std::uint64_t{kTimeHalfRange}) wraps_ += 1;
    last_time_ = time;
    out.push_back(wraps_ * kTimeRange + time, static_cast<std::uint16_t>(data & 0x3FFF),
                  static_cast<std::uint16_t>((data >> 14) & 0x3FFF),
                  (data >> 28) != 0 ? std::int8_t{1} : std::int8_t{-1});
  }

  std::string source_;
  TextHeader header_;
  int type_and_size_read_ = 0;
  WordSplitter<kRecordBytes> records_;
  std::uint32_t last_time_ = 0;
  Timestamp wraps_ = 0;
};

class DatEncoder final : public EventEncoder {
 public:
  explicit DatEncoder(SensorSize sensor) : sensor_(sensor) {}

  void write_header(std::vector<std::uint8_t>& out) const override {
    const std::string header = "% Data file containing CD events\n% Version 2\n% Width " +
                               std::to_string(sensor_.width) + "\n% Height " + std::to_string(sensor_.height) + "\n";
    out.insert(out.end(), header.begin(), header.end());
    out.push_back(kCdEventType);
    out.push_back(kRecordBytes);
  }

  void encode(const EventBatch& batch, std::vector<std::uint8_t>& out) override {
    check_encodable(batch, last_time_, kMaxCoordinate, "dat");
    // The 32-bit times can only be unwrapped if no step, from 0 to the first time and between events,
    // reaches 2^31 us.
    Timestamp previous = last_time_;
    for (const Timestamp t : batch.t) {
      if (t - previous >= Timestamp{kTimeHalfRange}) {
        throw std::invalid_argument("dat cannot encode the jump in time from " + std::to_string(previous) + " us to " +
                                    std::to_string(t) + " us (32-bit times: steps must stay below 2^31 us)");
      }
      previous = t;
    }
    for (std::size_t i = 0; i < batch.size(); ++i) {
      append_le32(static_cast<std::uint32_t>(batch.t[i] & std::numeric_limits<std::uint32_t>::max()), out);
      append_le32(static_cast<std::uint32_t>(batch.x[i]) | (static_cast<std::uint32_t>(batch.y[i]) << 14) |
                      (batch.p[i] > 0 ? 1u << 28 : 0u),
                  out);
    }
    if (!batch.empty()) last_time_ = batch.t.back();
  }

 private:
  SensorSize sensor_;
  Timestamp last_time_ = 0;
};

}  // namespace

std::unique_ptr<EventDecoder> make_dat_decoder(std::string source_name) {
  return std::make_unique<DatDecoder>(std::move(source_name));
}

std::unique_ptr<EventEncoder> make_dat_encoder(SensorSize sensor) {
  if (!sensor.valid() || sensor.width > kMaxCoordinate + 1 || sensor.height > kMaxCoordinate + 1) {
    throw std::invalid_argument("dat describes sensors up to 16384x16384, not " + std::to_string(sensor.width) + "x" +
                                std::to_string(sensor.height));
  }
  return std::make_unique<DatEncoder>(sensor);
}

}  // namespace evldt::detail
