#pragma once
// ROS 1 bags (format 2.0; chunks uncompressed, bz2 or lz4), read with Debian's rosbag_storage: the
// messages of one event topic in time order, as packets. Message types: dvs_msgs/EventArray (the
// Event Camera Dataset, MVSEC and the rpg_dvs_ros driver: events as 13-byte records) and
// event_camera_msgs/EventPacket (ros-event-camera's drivers: an encoded packet).

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "evldt/containers/packet_source.hpp"

namespace evldt {

inline constexpr std::string_view kRosbag1Magic = "#ROSBAG V2.0\n";

/// Opens a ROS 1 bag. `topic` empty: the first topic of an event message type. Throws
/// std::runtime_error naming the file if it is no readable bag or has no such topic (listing them).
std::unique_ptr<PacketSource> open_rosbag1(const std::filesystem::path& path, const std::string& topic);

class ImageSource;
/// The sensor_msgs/Image messages of a ROS 1 bag's topic (empty: the first topic of that type), in
/// time order. Throws std::runtime_error naming the file if it is no readable bag or has no such
/// topic (listing them).
std::unique_ptr<ImageSource> open_rosbag1_images(const std::filesystem::path& path, const std::string& topic);

}  // namespace evldt
