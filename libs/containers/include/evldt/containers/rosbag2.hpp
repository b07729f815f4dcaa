#pragma once
// ROS 2 bags in SQLite3 storage (.db3): the messages of one topic of an event type
// (event_camera_msgs/msg/EventPacket, dvs_msgs/msg/EventArray), in CDR, as packets.

#include <filesystem>
#include <memory>
#include <string>

#include "evldt/containers/packet_source.hpp"

namespace evldt {

/// Opens a bag's .db3 file. `topic` empty: the first topic of an event type. Throws
/// std::runtime_error naming the file if it is no ROS 2 bag or has no such topic (listing its topics).
std::unique_ptr<PacketSource> open_rosbag2(const std::filesystem::path& path, const std::string& topic);

}  // namespace evldt
