#pragma once
// Fixtures of ROS 1 bags for message types this project has no generated code for: a message given
// as its type name and serialized bytes, which rosbag_storage writes as it is.

#include <rosbag/bag.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

// A ROS 1 message given as its type name and serialized bytes, so that rosbag_storage can write
// fixtures of message types this project has no generated code for.
struct RawRosMessage {
  std::string type;
  std::vector<std::uint8_t> bytes;
  std::string definition;  ///< the message definition the bag stores for its connection
};

namespace ros::message_traits {
template <>
struct MD5Sum<RawRosMessage> {
  static const char* value(const RawRosMessage&) { return "*"; }
  static const char* value() { return "*"; }
};
template <>
struct DataType<RawRosMessage> {
  static const char* value(const RawRosMessage& message) { return message.type.c_str(); }
  static const char* value() { return "*"; }
};
template <>
struct Definition<RawRosMessage> {
  static const char* value(const RawRosMessage& message) { return message.definition.c_str(); }
  static const char* value() { return ""; }
};
}  // namespace ros::message_traits

namespace ros::serialization {
template <>
struct Serializer<RawRosMessage> {
  template <typename Stream>
  static void write(Stream& stream, const RawRosMessage& message) {
    std::memcpy(stream.advance(static_cast<std::uint32_t>(message.bytes.size())), message.bytes.data(),
                message.bytes.size());
  }
  static std::uint32_t serializedLength(const RawRosMessage& message) {
    return static_cast<std::uint32_t>(message.bytes.size());
  }
};
}  // namespace ros::serialization
