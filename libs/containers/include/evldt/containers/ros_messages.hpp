#pragma once
// The ROS event messages that bags (ROS 1 .bag, ROS 2 .db3, .mcap) carry, decoded from either ROS
// serialization into a packet of one encoding:
//   dvs_msgs/EventArray (rpg_dvs_ros; the Event Camera Dataset, MVSEC): header, height, width,
//     events[] of {uint16 x, uint16 y, time ts, bool polarity} -> encoding "dvs_events";
//   event_camera_msgs/EventPacket (ros-event-camera's drivers): header, height, width, seq,
//     time_base (ns), encoding, is_bigendian, uint8[] events -> the packet's own encoding.
// ROS 1 serialization is little-endian and packed; ROS 2's CDR aligns each primitive to its size.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evldt/containers/packet_source.hpp"

namespace evldt {

inline constexpr std::string_view kRos1EventArrayType = "dvs_msgs/EventArray";
inline constexpr std::string_view kRos1EventPacketType = "event_camera_msgs/EventPacket";
inline constexpr std::string_view kRos2EventArrayType = "dvs_msgs/msg/EventArray";
inline constexpr std::string_view kRos2EventPacketType = "event_camera_msgs/msg/EventPacket";

enum class RosSerialization { Ros1, Cdr };

/// Whether evldt decodes messages of `type` (a name of the serialization's ROS version).
bool is_event_message_type(RosSerialization serialization, std::string_view type);

/// The fields of an event message that a reader uses.
struct RosEventMessage {
  std::string frame_id;
  std::uint32_t width = 0, height = 0;
  std::string encoding;         ///< "dvs_events" for an EventArray, else the EventPacket's
  std::uint64_t time_base = 0;  ///< ns; EventPacket only
  std::span<const std::uint8_t> events;  ///< into the message, or into `scratch`
};

/// Decodes a message of an event type. An EventArray in CDR, whose records are padded by their
/// alignment, is repacked into `scratch` as dvs_events records. Throws std::runtime_error with the
/// reason (and offset) when the bytes are not such a message, or the event data is big-endian.
RosEventMessage decode_ros_event_message(RosSerialization serialization, std::string_view type,
                                         std::span<const std::uint8_t> bytes, std::vector<std::uint8_t>& scratch);

/// The message's events, encoding, time base and sensor size into `packet`.
void fill_packet(const RosEventMessage& message, RecordingPacket& packet);

}  // namespace evldt
