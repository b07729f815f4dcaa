#pragma once
// ROS 2 bags in SQLite3 storage (.db3): the messages of one topic of an event type
// (event_camera_msgs/msg/EventPacket, dvs_msgs/msg/EventArray), in CDR, as packets; or of one
// topic of images (sensor_msgs/msg/Image).

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "evldt/containers/packet_source.hpp"

namespace evldt {

inline constexpr std::string_view kSqliteMagic{"SQLite format 3\0", 16};

/// Opens a bag's .db3 file. `topic` empty: the first topic of an event type. Throws
/// std::runtime_error naming the file if it is no ROS 2 bag or has no such topic (listing its topics).
std::unique_ptr<PacketSource> open_rosbag2(const std::filesystem::path& path, const std::string& topic);

class ImageSource;
/// The sensor_msgs/msg/Image messages of a bag's topic (empty: the first topic of that type), in
/// time order. Throws std::runtime_error naming the file if it is no ROS 2 bag or has no such topic.
std::unique_ptr<ImageSource> open_rosbag2_images(const std::filesystem::path& path, const std::string& topic);

}  // namespace evldt
