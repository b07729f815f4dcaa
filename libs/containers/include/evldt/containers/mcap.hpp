#pragma once
// MCAP files (.mcap; rosbag2's default storage since ROS 2 Iron, Foxglove): the messages of one
// event topic, in file order (the order the recorder wrote them), as packets. Chunks may be
// uncompressed, LZ4 or Zstandard; their CRC is checked. Channels in CDR ("ros2msg" schemas) or ROS 1
// serialization ("ros1msg") with an event message type (ros_messages.hpp) are read.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "evldt/containers/packet_source.hpp"

namespace evldt {

inline constexpr std::string_view kMcapMagic{"\x89MCAP0\r\n", 8};

/// Opens an MCAP file and reads up to the channel to use. `topic` empty: the first channel of an
/// event type. Throws std::runtime_error naming the file if it is no MCAP file or has no such
/// channel (listing its channels).
std::unique_ptr<PacketSource> open_mcap(const std::filesystem::path& path, const std::string& topic);

class ImageSource;
/// The sensor_msgs/(msg/)Image messages of a channel (`topic`; empty: the first of that type), in
/// CDR or ROS 1 serialization, in file order. Throws std::runtime_error naming the file if it is no
/// MCAP file or has no such channel.
std::unique_ptr<ImageSource> open_mcap_images(const std::filesystem::path& path, const std::string& topic);

/// One channel's messages, whatever their encoding.
struct McapChannelMessages {
  struct Message {
    std::uint64_t log_time_ns;
    std::string data;
  };
  std::string topic, schema_name, schema_encoding, schema, message_encoding;
  std::vector<Message> messages;
};
/// Every message of channel `topic` (empty: the first channel) in file order, with its channel's
/// schema: for reading back what evldt wrote (evldt-export) and for tools. Throws std::runtime_error
/// naming the file if it is no MCAP file, is cut short, or has no such channel.
McapChannelMessages read_mcap_channel(const std::filesystem::path& path, const std::string& topic);

}  // namespace evldt
