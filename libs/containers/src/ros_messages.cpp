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
    if (count > (bytes_.size() - at_) / min_element_bytes)
      fail(std::to_string(count) + " elements do not fit in the message");
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

namespace {

// event_camera_msgs/EventPacket, as ros-event-camera's drivers define it.
constexpr std::string_view kEventPacketDefinition =
    "std_msgs/Header header\nuint32 height\nuint32 width\nuint64 seq\nuint64 time_base\nstring encoding\n"
    "bool is_bigendian\nuint8[] events\n";

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

bool is_header(std::string_view type) {
  return type == "Header" || type == "std_msgs/Header" || type == "std_msgs/msg/Header";
}

/// Bytes of a primitive field; 0 for a type that is not one.
std::size_t primitive_bytes(std::string_view type) {
  if (type == "bool" || type == "uint8" || type == "int8" || type == "byte" || type == "char") return 1;
  if (type == "uint16" || type == "int16") return 2;
  if (type == "uint32" || type == "int32" || type == "float32") return 4;
  if (type == "uint64" || type == "int64" || type == "float64") return 8;
  return 0;
}

}  // namespace

std::vector<RosEventLayout::Field> parse_message_fields(std::string_view definition) {
  std::vector<RosEventLayout::Field> fields;
  while (!definition.empty()) {
    const auto end = definition.find('\n');
    std::string_view line = definition.substr(0, end);
    definition = end == std::string_view::npos ? std::string_view{} : definition.substr(end + 1);
    if (line.starts_with("===")) break;  // the definitions of nested types follow
    line = trim(line.substr(0, line.find('#')));
    const auto space = line.find_first_of(" \t");
    if (line.empty() || space == std::string_view::npos) continue;
    const std::string_view type = line.substr(0, space);
    std::string_view name = trim(line.substr(space));
    if (name.find('=') != std::string_view::npos) continue;  // a constant
    name = name.substr(0, name.find_first_of(" \t"));        // ROS 2 may give a default value after the name
    fields.push_back({std::string(type), std::string(name)});
  }
  return fields;
}

std::optional<RosEventLayout> RosEventLayout::of(RosSerialization serialization, std::string_view type,
                                                 std::string_view definition) {
  RosEventLayout layout;
  layout.serialization_ = serialization;
  const bool ros1 = serialization == RosSerialization::Ros1;
  if (type == (ros1 ? kRos1EventArrayType : kRos2EventArrayType)) {
    layout.dvs_event_array_ = true;
    return layout;
  }
  const auto of_the_family = [](const std::vector<Field>& fields) {
    bool header = false, encoding = false, events = false;
    for (const Field& field : fields) {
      if (is_header(field.type)) {
        header = true;
      } else if (field.type == "string") {
        encoding = encoding || field.name == "encoding";
      } else if (field.type == "uint8[]" && field.name == "events") {
        events = true;
      } else if (primitive_bytes(field.type) == 0) {
        return false;  // arrays, nested messages: not of the family
      }
    }
    return header && encoding && events;
  };
  layout.fields_ = parse_message_fields(definition);
  if (of_the_family(layout.fields_)) return layout;
  // A known packet type whose stored definition is missing or unreadable: its published layout.
  if (type != (ros1 ? kRos1EventPacketType : kRos2EventPacketType)) return std::nullopt;
  layout.fields_ = parse_message_fields(kEventPacketDefinition);
  return layout;
}

RosEventMessage RosEventLayout::decode(std::span<const std::uint8_t> bytes, std::vector<std::uint8_t>& scratch) const {
  const bool ros1 = serialization_ == RosSerialization::Ros1;
  MessageReader reader(serialization_, bytes);
  RosEventMessage message;
  const auto read_header = [&] {
    if (ros1) reader.read<std::uint32_t>();  // header.seq (ROS 1 only)
    reader.read<std::uint32_t>();            // header.stamp.sec
    reader.read<std::uint32_t>();            // header.stamp.nsec
    message.frame_id = reader.read_string();
  };
  if (dvs_event_array_) {
    read_header();
    message.height = reader.read<std::uint32_t>();
    message.width = reader.read<std::uint32_t>();
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
  for (const Field& field : fields_) {
    if (is_header(field.type)) {
      read_header();
    } else if (field.type == "string") {
      std::string text = reader.read_string();
      if (field.name == "encoding") message.encoding = std::move(text);
    } else if (field.type == "uint8[]") {
      message.events = reader.read_bytes();
    } else {
      std::uint64_t value = 0;
      switch (primitive_bytes(field.type)) {
        case 1:
          value = reader.read<std::uint8_t>();
          break;
        case 2:
          value = reader.read<std::uint16_t>();
          break;
        case 4:
          value = reader.read<std::uint32_t>();
          break;
        default:
          value = reader.read<std::uint64_t>();
          break;
      }
      if (field.name == "width") message.width = static_cast<std::uint32_t>(value);
      if (field.name == "height") message.height = static_cast<std::uint32_t>(value);
      if (field.name == "time_base") message.time_base = value;
      if (field.name == "is_bigendian" && value != 0)
        throw std::runtime_error("big-endian event data is not supported");
    }
  }
  return message;
}

void fill_packet(const RosEventMessage& message, RecordingPacket& packet) {
  packet.bytes.assign(message.events.begin(), message.events.end());
  packet.encoding = message.encoding;
  packet.time_base_ns = static_cast<std::int64_t>(message.time_base);
  packet.sensor = sensor_of(message.width, message.height);
}

RecordingImage decode_ros_image(RosSerialization serialization, std::span<const std::uint8_t> bytes) {
  MessageReader reader(serialization, bytes);
  RecordingImage image;
  if (serialization == RosSerialization::Ros1) reader.read<std::uint32_t>();  // header.seq (ROS 1 only)
  const auto sec = reader.read<std::uint32_t>();
  const auto nsec = reader.read<std::uint32_t>();
  image.t_us = Timestamp{sec} * 1'000'000 + nsec / 1000;
  reader.read_string();  // header.frame_id
  image.height = reader.read<std::uint32_t>();
  image.width = reader.read<std::uint32_t>();
  image.encoding = reader.read_string();
  image.big_endian = reader.read<std::uint8_t>() != 0;
  image.step = reader.read<std::uint32_t>();
  image.data = reader.read_bytes();
  if (std::uint64_t{image.step} * image.height > image.data.size()) {
    throw std::runtime_error("an image of " + std::to_string(image.height) + " rows of " + std::to_string(image.step) +
                             " bytes holds only " + std::to_string(image.data.size()) + " bytes");
  }
  return image;
}

}  // namespace evldt
