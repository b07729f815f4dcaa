// Fuzz target for the checked decoding of event batches from raw LCM payload bytes. Checks: what
// decode_event_batch accepts, lcm-gen's own decoder also accepts whole and reads the same values;
// what it refuses leaves no events behind; its verdict on WrongType is exactly the fingerprint's.

#include <cstdint>
#include <span>

#include "evldt/transport/messages.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using evldt::fuzz::require;
  evldt::event_batch_t header;
  evldt::EventBatch events;
  const evldt::WireError error = evldt::decode_event_batch({data, size}, header, events);
  if (error != evldt::WireError::None) {
    require(events.empty(), "a refused batch left events behind");
    return 0;
  }
  // Accepted: then the generated decoder reads all of it (its forged-count hazard is excluded,
  // the counts having been checked) and finds the same message.
  evldt::event_batch_t generated;
  require(generated.decode(data, 0, static_cast<int>(size)) == static_cast<int>(size),
          "lcm-gen refuses an accepted batch");
  require(generated.utime == header.utime && generated.epoch == header.epoch && generated.seq == header.seq &&
              generated.source == header.source && generated.width == header.width &&
              generated.height == header.height && generated.t_base_us == header.t_base_us &&
              generated.num_events == header.num_events,
          "header fields differ from lcm-gen's");
  require(events.size() == static_cast<std::size_t>(generated.num_events), "event count differs");
  for (std::size_t i = 0; i < events.size(); ++i) {
    require(events.t[i] == generated.t_base_us + generated.dt_us[i], "event time differs");
    require(events.x[i] == static_cast<std::uint16_t>(generated.x[i]) &&
                events.y[i] == static_cast<std::uint16_t>(generated.y[i]),
            "event pixel differs");
    require(events.p[i] == (generated.polarity[i] ? 1 : -1), "event polarity differs");
  }
  return 0;
}
