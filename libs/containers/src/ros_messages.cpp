#include "evldt/containers/ros_messages.hpp"

#include <bit>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace evldt {
namespace {

constexpr std::size_t kDvsEventBytes = 13;  // dvs_events: uint16 x, uint16 y, uint32 sec, uint32 nsec, uint8 polarity

/// Primitives, strings and byte sequences of either serialization. CDR (OMG XCDR1, as ROS 2 writes
/// it) starts with a 4-byte encapsulation header (0x00 0x01 little-endian, 0x00 0x00 big-endian,
/// two option bytes) and aligns each primitive to its size, counted from after that header; its
/// strings count their NUL. ROS 1 is little-endian and packed, with strings without a NUL.
class MessageReader {
 public:
  MessageReader(RosSerialization serialization, std::span<const std::uint8_t> bytes)
      : bytes_(bytes), cdr_(serialization == RosSerialization::Cdr) {
    if (!cdr_) return;
    if (bytes.size() < 4 || bytes[0] != 0 || bytes[1] > 1) fail("no CDR encapsulation header");
    little_endian_ = bytes[1] == 1;
    body_ = at_ = 4;
  }
  template <typename T>
  T read() {
    align(sizeof(T));
    need(sizeof(T));
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    if (little_endian_ != (std::endian::native == std::endian::little)) value = byteswap(value);
    at_ += sizeof(T);
    return value;
  }
  std::string read_string() {
    const auto length = read<std::uint32_t>();
    if (!cdr_) return std::string(as_text(read_span(length)));
    if (length == 0) fail("string without its NUL");
    const auto text = read_span(length);
    if (text.back() != 0) fail("string not terminated");
    return std::string(as_text(text.first(length - 1)));
  }
  /// A uint32 count, then that many bytes.
  std::span<const std::uint8_t> read_bytes() { return read_span(read<std::uint32_t>()); }
  std::span<const std::uint8_t> read_span(std::size_t count) {
    need(count);
    const auto out = bytes_.subspan(at_, count);
    at_ += count;
    return out;
  }
  /// A sequence's element count, refused when the elements cannot fit in what is left.
  std::uint32_t read_count(std::size_t min_element_bytes) {
    const auto count = read<std::uint32_t>();
    if (count > (bytes_.size() - at_) / min_element_bytes) fail(std::to_string(count) + " elements do not fit in the message");
    return count;
  }

 private:
  static std::string_view as_text(std::span<const std::uint8_t> bytes) {
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }
  template <typename T>
  static T byteswap(T value) {
    std::uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }
  void align(std::size_t size) {
    if (!cdr_) return;
    const std::size_t misalign = (at_ - body_) % size;
    if (misalign != 0) {
      need(size - misalign);
      at_ += size - misalign;
    }
  }
  void need(std::size_t count) const {
    if (count > bytes_.size() - at_) fail("message ends early (" + std::to_string(count) + " more bytes needed)");
  }
  [[noreturn]] void fail(const std::string& reason) const {
    throw std::runtime_error(std::string(cdr_ ? "CDR" : "message") + " byte " + std::to_string(at_) + ": " + reason);
  }

  std::span<const std::uint8_t> bytes_;
  bool cdr_;
  bool little_endian_ = true;
  std::size_t body_ = 0;
  std::size_t at_ = 0;
};

void append_le(std::vector<std::uint8_t>& out, std::uint32_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

}  // namespace

bool is_event_message_type(RosSerialization serialization, std::string_view type) {
  return serialization == RosSerialization::Ros1 ? (type == kRos1EventArrayType || type == kRos1EventPacketType)
                                                 : (type == kRos2EventArrayType || type == kRos2EventPacketType);
}

RosEventMessage decode_ros_event_message(RosSerialization serialization, std::string_view type,
                                         std::span<const std::uint8_t> bytes, std::vector<std::uint8_t>& scratch) {
  const bool ros1 = serialization == RosSerialization::Ros1;
  if (!is_event_message_type(serialization, type)) throw std::runtime_error("type " + std::string(type) + " holds no events evldt reads");
  MessageReader reader(serialization, bytes);
  RosEventMessage message;
  if (ros1) reader.read<std::uint32_t>();  // header.seq (ROS 1 only)
  reader.read<std::uint32_t>();            // header.stamp.sec
  reader.read<std::uint32_t>();            // header.stamp.nsec
  message.frame_id = reader.read_string();
  message.height = reader.read<std::uint32_t>();
  message.width = reader.read<std::uint32_t>();
  if (type == kRos1EventArrayType || type == kRos2EventArrayType) {
    message.encoding = "dvs_events";
    if (ros1) {
      message.events = reader.read_span(std::size_t{reader.read_count(kDvsEventBytes)} * kDvsEventBytes);
      return message;
    }
    const std::uint32_t count = reader.read_count(kDvsEventBytes);
    scratch.clear();
    scratch.reserve(std::size_t{count} * kDvsEventBytes);
    for (std::uint32_t i = 0; i < count; ++i) {
      append_le(scratch, reader.read<std::uint16_t>(), 2);  // x
      append_le(scratch, reader.read<std::uint16_t>(), 2);  // y
      append_le(scratch, reader.read<std::uint32_t>(), 4);  // ts.sec
      append_le(scratch, reader.read<std::uint32_t>(), 4);  // ts.nanosec
      scratch.push_back(reader.read<std::uint8_t>());       // polarity
    }
    message.events = scratch;
    return message;
  }
  reader.read<std::uint64_t>();  // seq
  message.time_base = reader.read<std::uint64_t>();
  message.encoding = reader.read_string();
  if (reader.read<std::uint8_t>() != 0) throw std::runtime_error("big-endian event data is not supported");
  message.events = reader.read_bytes();
  return message;
}

void fill_packet(const RosEventMessage& message, RecordingPacket& packet) {
  packet.bytes.assign(message.events.begin(), message.events.end());
  packet.encoding = message.encoding;
  packet.time_base_ns = static_cast<std::int64_t>(message.time_base);
  packet.sensor = sensor_of(message.width, message.height);
}

}  // namespace evldt
