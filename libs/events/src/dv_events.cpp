// "dv_events": iniVation's polarity event packet, the payload of an AEDAT 4.0 "EVTS" stream after
// decompression: a size-prefixed FlatBuffer (schemas/dv_events.fbs) of 16-byte events, t (us), x, y,
// polarity, in DV's layout or the aedat library's (size_prefixed_flatbuffer.hpp). A container hands
// each packet whole, in one decode() call. The buffer is verified before any field is read.

#include <flatbuffers/flatbuffers.h>

#include <vector>

#include "dv_events_generated.h"
#include "evldt/events/event_decoder.hpp"
#include "evldt/events/size_prefixed_flatbuffer.hpp"

namespace evldt::detail {
namespace {

class DvEventsDecoder final : public EventDecoder {
 public:
  explicit DvEventsDecoder(std::string source) : source_(std::move(source)) {}

  void decode(std::span<const std::uint8_t> packet, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    // The identifier EVTS is DV's; other writers leave it out, so it is not required.
    const dv::EventPacket* events = verified_size_prefixed_root<dv::EventPacket>(packet, aligned_);
    if (events == nullptr) throw FormatError(source_, 0, "not a valid size-prefixed FlatBuffer event packet");
    if (events->elements() == nullptr) return;
    for (const dv::Event* event : *events->elements()) {
      if (event->x() < 0 || event->y() < 0) {
        ++counts_.skipped_words;  // a negative coordinate is no pixel of any sensor
        continue;
      }
      out.push_back(event->timestamp(), static_cast<std::uint16_t>(event->x()), static_cast<std::uint16_t>(event->y()),
                    event->polarity() ? std::int8_t{1} : std::int8_t{-1});
    }
  }
  void finish(EventBatch&) override {}
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }
  [[nodiscard]] DecodeCounts counts() const override { return counts_; }

 private:
  std::string source_;
  DecodeCounts counts_;
  std::vector<std::uint64_t> aligned_;
};

}  // namespace

std::unique_ptr<EventDecoder> make_dv_events_decoder(std::string source_name) {
  return std::make_unique<DvEventsDecoder>(std::move(source_name));
}

}  // namespace evldt::detail
