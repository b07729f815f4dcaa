#include "evldt/containers/rosbag1.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <cstring>
#include <stdexcept>

#include "evldt/containers/rosbag2.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {
namespace {

// ROS 1 serialization: little-endian, no padding; a string or array is a uint32 count, then the
// elements.
class Ros1Reader {
 public:
  explicit Ros1Reader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  template <typename T>
  T read() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::string read_string() {
    const auto bytes = read_span(read<std::uint32_t>());
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }
  std::span<const std::uint8_t> read_span(std::size_t count) {
    need(count);
    const auto out = bytes_.subspan(at_, count);
    at_ += count;
    return out;
  }

 private:
  void need(std::size_t count) const {
    if (count > bytes_.size() - at_) {
      throw std::runtime_error("message ends early at byte " + std::to_string(at_) + " (" + std::to_string(count) +
                               " more bytes needed)");
    }
  }
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

constexpr std::size_t kDvsEventBytes = 13;  // uint16 x, uint16 y, time ts (uint32 sec, nsec), uint8 polarity

bool is_event_type(const std::string& type) { return type == kDvsEventArrayType || type == kEventPacketType; }

class Rosbag1Source final : public PacketSource {
 public:
  Rosbag1Source(const std::filesystem::path& path, const std::string& topic) : path_(path.string()) {
    try {
      bag_.open(path_, rosbag::bagmode::Read);
      rosbag::View all(bag_);
      std::string listing;
      for (const rosbag::ConnectionInfo* connection : all.getConnections()) {
        listing += (listing.empty() ? "" : ", ") + connection->topic + " (" + connection->datatype + ")";
        if (!topic_.empty()) continue;
        if (topic.empty() ? is_event_type(connection->datatype) : connection->topic == topic) {
          if (!is_event_type(connection->datatype)) {
            throw std::runtime_error("topic " + topic + " is of type " + connection->datatype + ", not " + kDvsEventArrayType +
                                     " or " + kEventPacketType);
          }
          topic_ = connection->topic;
          type_ = connection->datatype;
        }
      }
      if (topic_.empty()) {
        throw std::runtime_error((topic.empty() ? std::string("no topic of an event type") : "no topic " + topic) +
                                 " (topics: " + (listing.empty() ? "none" : listing) + ")");
      }
      view_.emplace(bag_, rosbag::TopicQuery(topic_));
      total_ = view_->size();
      next_ = view_->begin();
    } catch (const rosbag::BagException& error) {
      throw std::runtime_error("'" + path_ + "' is not a readable ROS 1 bag: " + error.what());
    } catch (const std::runtime_error& error) {
      throw std::runtime_error("'" + path_ + "': " + error.what());
    }
  }

  bool next(RecordingPacket& packet) override {
    try {
      if (next_ == view_->end()) return false;
      const rosbag::MessageInstance& message = *next_;
      packet.location = "message " + std::to_string(read_) + " of " + topic_;
      buffer_.resize(message.size());
      ros::serialization::OStream stream(buffer_.data(), static_cast<std::uint32_t>(buffer_.size()));
      message.write(stream);
      const Ros1EventMessage decoded = decode_ros1_event_message(message.getDataType(), buffer_);
      packet.bytes.assign(decoded.events.begin(), decoded.events.end());
      packet.encoding = decoded.encoding;
      packet.time_base_ns = static_cast<std::int64_t>(decoded.time_base);
      packet.sensor = sensor_of(decoded.width, decoded.height);
      if (camera_.empty()) camera_ = decoded.frame_id;
      ++read_;
      ++next_;
      return true;
    } catch (const rosbag::BagException& error) {
      throw FormatError(path_, 0, packet.location + ": " + error.what());
    } catch (const std::runtime_error& error) {
      throw FormatError(path_, 0, packet.location + ": " + error.what());
    }
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }  // in the messages
  [[nodiscard]] std::string camera() const override { return camera_; }
  [[nodiscard]] std::string description() const override { return "ROS 1 bag, " + topic_ + " (" + type_ + ")"; }
  [[nodiscard]] double progress() const override {
    return total_ == 0 ? 1.0 : static_cast<double>(read_) / static_cast<double>(total_);
  }
  [[nodiscard]] std::uint64_t skipped_packets() const override { return 0; }  // other topics are not read

 private:
  std::string path_;
  rosbag::Bag bag_;
  std::string topic_, type_, camera_;
  std::optional<rosbag::View> view_;
  rosbag::View::iterator next_;
  std::uint64_t total_ = 0, read_ = 0;
  std::vector<std::uint8_t> buffer_;
};

}  // namespace

Ros1EventMessage decode_ros1_event_message(std::string_view type, std::span<const std::uint8_t> bytes) {
  Ros1Reader reader(bytes);
  Ros1EventMessage message;
  reader.read<std::uint32_t>();  // header.seq
  reader.read<std::uint32_t>();  // header.stamp.sec
  reader.read<std::uint32_t>();  // header.stamp.nsec
  message.frame_id = reader.read_string();
  message.height = reader.read<std::uint32_t>();
  message.width = reader.read<std::uint32_t>();
  if (type == kDvsEventArrayType) {
    const auto count = reader.read<std::uint32_t>();
    if (count > bytes.size() / kDvsEventBytes) throw std::runtime_error(std::to_string(count) + " events do not fit in the message");
    message.encoding = "dvs_events";
    message.events = reader.read_span(std::size_t{count} * kDvsEventBytes);
  } else if (type == kEventPacketType) {
    reader.read<std::uint64_t>();  // seq
    message.time_base = reader.read<std::uint64_t>();
    message.encoding = reader.read_string();
    if (reader.read<std::uint8_t>() != 0) throw std::runtime_error("big-endian event data is not supported");
    message.events = reader.read_span(reader.read<std::uint32_t>());
  } else {
    throw std::runtime_error("type " + std::string(type) + " holds no events evldt reads");
  }
  return message;
}

std::unique_ptr<PacketSource> open_rosbag1(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<Rosbag1Source>(path, topic);
}

}  // namespace evldt
