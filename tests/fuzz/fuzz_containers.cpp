// Fuzz target for the recording containers: the first input byte picks AEDAT 4.0 (the rest follows
// its version line), a CDR EventPacket message (ROS 2), or a ROS 1 dvs_msgs/EventArray or
// EventPacket message. Checks: only std::runtime_error (FormatError or a refused file) escapes, a
// reader stops for good after its error, and a decoded message's event bytes lie inside the message.

#include <stdexcept>
#include <vector>

#include "evldt/containers/aedat4.hpp"
#include "evldt/containers/rosbag1.hpp"
#include "evldt/containers/rosbag2.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  using evldt::fuzz::require;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  const auto inside = [&](std::span<const std::uint8_t> events) {
    return events.empty() || (events.data() >= rest.data() && events.data() + events.size() <= rest.data() + rest.size());
  };
  switch (data[0] % 4) {
    case 0:
      try {
        require(inside(evldt::decode_event_packet_cdr(rest).events), "event bytes outside the message");
      } catch (const std::runtime_error&) {
      }
      return 0;
    case 2:
    case 3:
      try {
        const auto type = data[0] % 4 == 2 ? evldt::kDvsEventArrayType : evldt::kEventPacketType;
        require(inside(evldt::decode_ros1_event_message(type, rest).events), "event bytes outside the message");
      } catch (const std::runtime_error&) {
      }
      return 0;
    default: break;
  }
  std::vector<std::uint8_t> file(evldt::kAedat4Magic.begin(), evldt::kAedat4Magic.end());
  file.insert(file.end(), rest.begin(), rest.end());
  const evldt::fuzz::TempFile temp(file, ".aedat4");
  try {
    evldt::PacketEventReader reader(evldt::open_aedat4(temp.path()), "fuzz");
    (void)reader.geometry();
    evldt::EventBatch batch;
    evldt::fuzz::read_to_the_end(reader, batch);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
