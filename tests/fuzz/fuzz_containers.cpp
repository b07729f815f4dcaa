// Fuzz target for the recording containers: the first input byte picks AEDAT 4.0 (the rest follows
// its version line) or a bare CDR EventPacket message. Checks: only std::runtime_error (FormatError
// or a refused file) escapes, a reader stops for good after its error, and a decoded message's
// event bytes lie inside the message.

#include <stdexcept>
#include <vector>

#include "evldt/containers/aedat4.hpp"
#include "evldt/containers/rosbag2.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  using evldt::fuzz::require;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  if (data[0] % 2 == 0) {
    try {
      const evldt::EventPacketMessage message = evldt::decode_event_packet_cdr(rest);
      require(message.events.data() >= rest.data() && message.events.data() + message.events.size() <= rest.data() + rest.size(),
              "event bytes outside the message");
    } catch (const std::runtime_error&) {
    }
    return 0;
  }
  std::vector<std::uint8_t> file(evldt::kAedat4Magic.begin(), evldt::kAedat4Magic.end());
  file.insert(file.end(), rest.begin(), rest.end());
  const evldt::fuzz::TempFile temp(file, ".aedat4");
  try {
    evldt::PacketEventReader reader(evldt::open_aedat4(temp.path()), "fuzz");
    (void)reader.geometry();
    evldt::EventBatch batch;
    bool failed = false;
    try {
      while (reader.read(batch)) require(!batch.empty(), "read() returned true with no events");
    } catch (const evldt::FormatError&) {
      failed = true;
    }
    if (failed) require(!reader.read(batch) && batch.empty(), "the reader went on after its error");
  } catch (const std::runtime_error&) {
  }
  return 0;
}
