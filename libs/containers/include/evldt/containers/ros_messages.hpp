#pragma once
// The ROS event messages that bags (ROS 1 .bag, ROS 2 .db3, .mcap) carry, decoded from either ROS
// serialization into a packet of one encoding:
//   dvs_msgs/EventArray (rpg_dvs_ros; the Event Camera Dataset, MVSEC): header, height, width,
//     events[] of {uint16 x, uint16 y, time ts, bool polarity} -> encoding "dvs_events";
//   event_camera_msgs/EventPacket (ros-event-camera's drivers): header, height, width, seq,
//     time_base (ns), encoding, is_bigendian, uint8[] events -> the packet's own encoding.
//   any message of that packet family (event_array_msgs/EventArray, its former name, among them),
//     read by the fields of the message definition the bag stores: a header, a string encoding, a
//     uint8[] of events, and primitive fields (width, height, time_base, is_bigendian...) in any order.
// ROS 1 serialization is little-endian and packed; ROS 2's CDR aligns each primitive to its size.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evldt/containers/image_source.hpp"
#include "evldt/containers/packet_source.hpp"

namespace evldt {

inline constexpr std::string_view kRos1EventArrayType = "dvs_msgs/EventArray";
inline constexpr std::string_view kRos1EventPacketType = "event_camera_msgs/EventPacket";
inline constexpr std::string_view kRos2EventArrayType = "dvs_msgs/msg/EventArray";
inline constexpr std::string_view kRos2EventPacketType = "event_camera_msgs/msg/EventPacket";

enum class RosSerialization { Ros1, Cdr };

/// The fields of an event message that a reader uses.
struct RosEventMessage {
  std::string frame_id;
  std::uint32_t width = 0, height = 0;
  std::string encoding;                  ///< "dvs_events" for an EventArray, else the EventPacket's
  std::uint64_t time_base = 0;           ///< ns; EventPacket only
  std::span<const std::uint8_t> events;  ///< into the message, or into `scratch`
};

/// How one topic's messages are read.
class RosEventLayout {
 public:
  /// The layout for messages of `type` as `definition` (the message definition a bag stores for the
  /// topic, empty where it stores none) describes them: dvs_msgs/EventArray, or a message of the
  /// packet family (event_camera_msgs/EventPacket is known without a definition); nullopt if such
  /// messages hold no events evldt reads.
  static std::optional<RosEventLayout> of(RosSerialization serialization, std::string_view type,
                                          std::string_view definition);

  /// Decodes a message. An EventArray in CDR, whose records are padded by their alignment, is repacked
  /// into `scratch` as dvs_events records. Throws std::runtime_error with the reason (and offset)
  /// when the bytes are not such a message, or the event data is big-endian.
  RosEventMessage decode(std::span<const std::uint8_t> bytes, std::vector<std::uint8_t>& scratch) const;

  /// One top-level field of a message definition: its type and name ("uint32", "width").
  struct Field {
    std::string type;
    std::string name;
  };

 private:
  RosSerialization serialization_ = RosSerialization::Ros1;
  bool dvs_event_array_ = false;
  std::vector<Field> fields_;  // of a packet-family message
};

/// The top-level fields of a ROS message definition as bags store it: "TYPE NAME" lines up to the
/// first "===" line (the definitions of nested types follow it); comments, constants and blank
/// lines skipped.
std::vector<RosEventLayout::Field> parse_message_fields(std::string_view definition);

/// The message types evldt reads without a definition, for messages naming what it wanted.
inline constexpr std::string_view kKnownEventTypes =
    "dvs_msgs/EventArray, event_camera_msgs/EventPacket, or a message of that family with its definition";

/// The message's events, encoding, time base and sensor size into `packet`.
void fill_packet(const RosEventMessage& message, RecordingPacket& packet);

inline constexpr std::string_view kRos1ImageType = "sensor_msgs/Image";
inline constexpr std::string_view kRos2ImageType = "sensor_msgs/msg/Image";

/// Decodes a sensor_msgs/Image (a DAVIS's APS frame in the Event Camera Dataset's and MVSEC's
/// bags): header, height, width, encoding, is_bigendian, step, data; header.stamp on the clock of
/// the events (dvs_events: sec * 10^6 + nsec / 1000 us). Throws std::runtime_error with the reason
/// (and offset) when the bytes are not such a message or hold fewer than step * height bytes of data.
RecordingImage decode_ros_image(RosSerialization serialization, std::span<const std::uint8_t> bytes);

}  // namespace evldt
