#pragma once
// ROS 1 bags (format 2.0; chunks uncompressed, bz2 or lz4), read with Debian's rosbag_storage: the
// messages of one event topic in time order, as packets. Message types: dvs_msgs/EventArray (the
// Event Camera Dataset, MVSEC and the rpg_dvs_ros driver: events as 13-byte records) and
// event_camera_msgs/EventPacket (ros-event-camera's drivers: an encoded packet).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "evldt/containers/packet_source.hpp"

namespace evldt {

inline constexpr std::string_view kRosbag1Magic = "#ROSBAG V2.0\n";
inline constexpr const char* kDvsEventArrayType = "dvs_msgs/EventArray";

/// A ROS 1 message's fields that matter here, from its serialized bytes (little-endian, packed).
struct Ros1EventMessage {
  std::string frame_id;
  std::uint32_t width = 0, height = 0;
  std::string encoding;         ///< "dvs_events" for an EventArray, else the EventPacket's
  std::uint64_t time_base = 0;  ///< EventPacket only
  std::span<const std::uint8_t> events;
};

/// Decodes a dvs_msgs/EventArray or event_camera_msgs/EventPacket (`type`); throws
/// std::runtime_error with the reason when the bytes are not such a message.
Ros1EventMessage decode_ros1_event_message(std::string_view type, std::span<const std::uint8_t> bytes);

/// Opens a ROS 1 bag. `topic` empty: the first topic of an event message type. Throws
/// std::runtime_error naming the file if it is no readable bag or has no such topic (listing them).
std::unique_ptr<PacketSource> open_rosbag1(const std::filesystem::path& path, const std::string& topic);

}  // namespace evldt
