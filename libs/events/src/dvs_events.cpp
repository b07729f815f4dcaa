// "dvs_events": the events of a dvs_msgs/EventArray (rpg_dvs_ros; the Event Camera Dataset and
// MVSEC bags), as a ROS 1 bag stores them: packed little-endian 13-byte records,
//   uint16 x, uint16 y, uint32 ts.sec, uint32 ts.nsec, uint8 polarity (non-zero: ON).
// t = sec * 10^6 + nsec / 1000 us (the ROS time of the event).

#include "evldt/events/event_decoder.hpp"

namespace evldt::detail {
namespace {

constexpr std::size_t kRecordBytes = 13;

class DvsEventsDecoder final : public EventDecoder {
 public:
  explicit DvsEventsDecoder(std::string source) : source_(std::move(source)) {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    records_.feed(chunk, [&](const std::uint8_t* record, std::uint64_t) {
      const Timestamp t = Timestamp{load_le32(record + 4)} * 1'000'000 + load_le32(record + 8) / 1000;
      out.push_back(t, load_le16(record), load_le16(record + 2), record[12] != 0 ? std::int8_t{1} : std::int8_t{-1});
    });
  }
  void finish(EventBatch&) override {
    if (records_.carried() > 0) throw FormatError(source_, records_.offset(), "data ends inside a 13-byte dvs event");
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }

 private:
  std::string source_;
  WordSplitter<kRecordBytes> records_;
};

}  // namespace

std::unique_ptr<EventDecoder> make_dvs_events_decoder(std::string source_name) {
  return std::make_unique<DvsEventsDecoder>(std::move(source_name));
}

}  // namespace evldt::detail
