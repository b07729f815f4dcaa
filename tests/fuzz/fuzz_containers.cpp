// Fuzz target for the recording containers: the first input byte picks a ROS event message (CDR or
// ROS 1 serialization; dvs_msgs/EventArray or event_camera_msgs/EventPacket), an AEDAT 4.0 file or
// an MCAP file (the rest follows the format's magic). Checks: only std::runtime_error (FormatError
// or a refused file) escapes, a reader stops for good after its error, and a decoded message's
// event bytes lie inside the message (a repacked CDR EventArray: whole 13-byte records).

#include <stdexcept>
#include <string_view>
#include <vector>

#include "evldt/containers/aedat4.hpp"
#include "evldt/containers/mcap.hpp"
#include "evldt/containers/ros_messages.hpp"
#include "fuzz_support.hpp"

namespace {

void fuzz_message(evldt::RosSerialization serialization, std::string_view type, std::span<const std::uint8_t> bytes) {
  std::vector<std::uint8_t> scratch;
  try {
    const auto layout = evldt::RosEventLayout::of(serialization, type, "");
    const auto events = layout->decode(bytes, scratch).events;
    const bool in_message = events.empty() || (events.data() >= bytes.data() && events.data() + events.size() <= bytes.data() + bytes.size());
    const bool repacked = events.data() == scratch.data() && events.size() == scratch.size() && events.size() % 13 == 0;
    evldt::fuzz::require(in_message || repacked, "event bytes outside the message");
  } catch (const std::runtime_error&) {
  }
}

void fuzz_file(std::string_view magic, std::span<const std::uint8_t> rest, const char* suffix) {
  std::vector<std::uint8_t> file(magic.begin(), magic.end());
  file.insert(file.end(), rest.begin(), rest.end());
  const evldt::fuzz::TempFile temp(file, suffix);
  try {
    evldt::PacketEventReader reader(magic == evldt::kMcapMagic ? evldt::open_mcap(temp.path(), "") : evldt::open_aedat4(temp.path()), "fuzz");
    (void)reader.geometry();
    evldt::EventBatch batch;
    evldt::fuzz::read_to_the_end(reader, batch);
  } catch (const std::runtime_error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  using evldt::RosSerialization;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  switch (data[0] % 6) {
    case 0: fuzz_message(RosSerialization::Cdr, evldt::kRos2EventPacketType, rest); break;
    case 1: fuzz_message(RosSerialization::Cdr, evldt::kRos2EventArrayType, rest); break;
    case 2: fuzz_message(RosSerialization::Ros1, evldt::kRos1EventArrayType, rest); break;
    case 3: fuzz_message(RosSerialization::Ros1, evldt::kRos1EventPacketType, rest); break;
    case 4: fuzz_file(evldt::kAedat4Magic, rest, ".aedat4"); break;
    default: fuzz_file(evldt::kMcapMagic, rest, ".mcap"); break;
  }
  return 0;
}
