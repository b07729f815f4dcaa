#pragma once
// ROS 2 bags in SQLite3 storage (.db3): the messages of one topic of type
// event_camera_msgs/msg/EventPacket, in CDR, as packets.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>

#include "evldt/containers/packet_source.hpp"

namespace evldt {

inline constexpr const char* kEventPacketType = "event_camera_msgs/msg/EventPacket";

/// The fields of an event_camera_msgs/msg/EventPacket (header, height, width, seq, time_base,
/// encoding, is_bigendian, events), decoded from CDR (either byte order). `events` points into the
/// decoded bytes.
struct EventPacketMessage {
  std::string frame_id;
  std::uint32_t width = 0, height = 0;
  std::uint64_t seq = 0;
  std::uint64_t time_base = 0;
  std::string encoding;
  bool is_bigendian = false;
  std::span<const std::uint8_t> events;
};

/// Throws std::runtime_error with the reason (and offset) when the bytes are not such a message.
EventPacketMessage decode_event_packet_cdr(std::span<const std::uint8_t> cdr);

/// Opens a bag's .db3 file. `topic` empty: the first topic of type EventPacket. Throws
/// std::runtime_error naming the file if it is no ROS 2 bag or has no such topic (listing its topics).
std::unique_ptr<PacketSource> open_rosbag2(const std::filesystem::path& path, const std::string& topic);

}  // namespace evldt
