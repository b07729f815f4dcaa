// Fuzz target for the recording containers: the first input byte picks a ROS event message (CDR or
// ROS 1 serialization; dvs_msgs/EventArray or event_camera_msgs/EventPacket), an AEDAT 4.0 file or
// an MCAP file read for events, or an AEDAT 4.0, 3.1 or 2.0 file read for frames (the rest follows
// the format's magic). Checks: only std::runtime_error (FormatError or a refused file) escapes, a
// reader stops for good after its error, a decoded message's event bytes lie inside the message (a
// repacked CDR EventArray: whole 13-byte records), and an image's rows lie inside its bytes.

#include <stdexcept>
#include <string_view>
#include <vector>

#include "evldt/containers/aedat4.hpp"
#include "evldt/containers/aedat_images.hpp"
#include "evldt/containers/image_source.hpp"
#include "evldt/containers/mcap.hpp"
#include "evldt/containers/ros_messages.hpp"
#include "fuzz_support.hpp"

namespace {

void fuzz_message(evldt::RosSerialization serialization, std::string_view type, std::span<const std::uint8_t> bytes) {
  std::vector<std::uint8_t> scratch;
  try {
    const auto layout = evldt::RosEventLayout::of(serialization, type, "");
    const auto events = layout->decode(bytes, scratch).events;
    const bool in_message = events.empty() || (events.data() >= bytes.data() &&
                                               events.data() + events.size() <= bytes.data() + bytes.size());
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
    evldt::PacketEventReader reader(
        magic == evldt::kMcapMagic ? evldt::open_mcap(temp.path(), "") : evldt::open_aedat4(temp.path()), "fuzz");
    (void)reader.geometry();
    evldt::EventBatch batch;
    evldt::fuzz::read_to_the_end(reader, batch);
  } catch (const std::runtime_error&) {
  }
}

void fuzz_images(std::string_view magic, std::span<const std::uint8_t> rest, const char* suffix) {
  std::vector<std::uint8_t> file(magic.begin(), magic.end());
  file.insert(file.end(), rest.begin(), rest.end());
  const evldt::fuzz::TempFile temp(file, suffix);
  try {
    const auto images = evldt::open_image_container(temp.path(), "");
    evldt::fuzz::require(images != nullptr, "a file with a frame container's magic was not recognised");
    evldt::RecordingImage image;
    std::string location;
    while (images->next(image, location)) {
      evldt::fuzz::require(image.data.size() >= std::size_t{image.step} * image.height,
                           "an image's rows lie outside its bytes");
    }
  } catch (const std::runtime_error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  using evldt::RosSerialization;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  switch (data[0] % 9) {
    case 0:
      fuzz_message(RosSerialization::Cdr, evldt::kRos2EventPacketType, rest);
      break;
    case 1:
      fuzz_message(RosSerialization::Cdr, evldt::kRos2EventArrayType, rest);
      break;
    case 2:
      fuzz_message(RosSerialization::Ros1, evldt::kRos1EventArrayType, rest);
      break;
    case 3:
      fuzz_message(RosSerialization::Ros1, evldt::kRos1EventPacketType, rest);
      break;
    case 4:
      fuzz_file(evldt::kAedat4Magic, rest, ".aedat4");
      break;
    case 5:
      fuzz_file(evldt::kMcapMagic, rest, ".mcap");
      break;
    case 6:
      fuzz_images(evldt::kAedat4Magic, rest, ".aedat4");
      break;
    case 7:
      fuzz_images(evldt::kAedat31Magic, rest, ".aedat");
      break;
    default:
      fuzz_images(evldt::kAedat2Magic, rest, ".aedat");
      break;
  }
  return 0;
}
