// "mono": the plain encoding of ros-event-camera's event_camera_codecs for an event_camera_msgs/
// EventPacket, one little-endian 64-bit word per event:
//   [31:0] time since the packet's time base (ns), [47:32] x, [62:48] y, [63] polarity (1 ON).
// t = (time_base + time) ns, in us rounded down.

#include "evldt/events/event_decoder.hpp"

namespace evldt::detail {
namespace {

class MonoDecoder final : public EventDecoder {
 public:
  explicit MonoDecoder(std::string source) : source_(std::move(source)) {}
  // The base splits into us and the ns left over, so that base + time cannot overflow.
  void start_packet(std::int64_t time_base_ns) override {
    base_us_ = floor_ns_to_us(time_base_ns);
    base_ns_left_ = time_base_ns % 1000 + (time_base_ns % 1000 < 0 ? 1000 : 0);
  }

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    words_.feed(chunk, [&](const std::uint8_t* word, std::uint64_t) {
      const std::uint32_t high = load_le32(word + 4);
      out.push_back(base_us_ + static_cast<Timestamp>((base_ns_left_ + load_le32(word)) / 1000),
                    static_cast<std::uint16_t>(high & 0xFFFF), static_cast<std::uint16_t>((high >> 16) & 0x7FFF),
                    (high >> 31) != 0 ? std::int8_t{1} : std::int8_t{-1});
    });
  }
  void finish(EventBatch&) override {
    if (words_.carried() > 0) throw FormatError(source_, words_.offset(), "mono data ends inside an 8-byte event");
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }

 private:
  std::string source_;
  WordSplitter<8> words_;
  Timestamp base_us_ = 0;
  std::int64_t base_ns_left_ = 0;  // 0..999
};

}  // namespace

std::unique_ptr<EventDecoder> make_mono_decoder(std::string source_name) {
  return std::make_unique<MonoDecoder>(std::move(source_name));
}

}  // namespace evldt::detail
