#include "evldt/containers/rosbag1.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <functional>
#include <stdexcept>

#include "evldt/containers/ros_messages.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {
namespace {

/// One topic of a bag, read in time order as serialized messages: the topic `wanted`, or if empty
/// the first whose connection `accepts`. For errors, `kind` names what it looks for ("an event
/// type") and `expected` the types it accepts. Throws std::runtime_error naming the file for a bag
/// it cannot read or no such topic.
class Rosbag1Topic {
 public:
  Rosbag1Topic(const std::filesystem::path& path, const std::string& wanted,
               const std::function<bool(const rosbag::ConnectionInfo&)>& accepts, const std::string& kind,
               const std::string& expected)
      : path_(path.string()) {
    try {
      bag_.open(path_, rosbag::bagmode::Read);
      rosbag::View all(bag_);
      std::string listing;
      for (const rosbag::ConnectionInfo* connection : all.getConnections()) {
        listing += (listing.empty() ? "" : ", ") + connection->topic + " (" + connection->datatype + ")";
        if (!topic_.empty() || (wanted.empty() ? !accepts(*connection) : connection->topic != wanted)) continue;
        if (!accepts(*connection))
          throw std::runtime_error("topic " + wanted + " is of type " + connection->datatype + ", not " + expected);
        topic_ = connection->topic;
        type_ = connection->datatype;
        definition_ = connection->msg_def;
      }
      if (topic_.empty()) {
        throw std::runtime_error((wanted.empty() ? "no topic of " + kind : "no topic " + wanted) +
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

  /// The next message's bytes; false at the end. Throws rosbag::BagException for one it cannot read.
  bool next(std::vector<std::uint8_t>& bytes) {
    if (next_ == view_->end()) return false;
    const rosbag::MessageInstance& message = *next_;
    bytes.resize(message.size());
    ros::serialization::OStream stream(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
    message.write(stream);
    ++read_;
    ++next_;
    return true;
  }
  /// "message 3 of /dvs/events": the message next() returns next.
  [[nodiscard]] std::string location() const { return "message " + std::to_string(read_) + " of " + topic_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] const std::string& topic() const { return topic_; }
  [[nodiscard]] const std::string& type() const { return type_; }
  [[nodiscard]] const std::string& definition() const { return definition_; }
  [[nodiscard]] double progress() const {
    return total_ == 0 ? 1.0 : static_cast<double>(read_) / static_cast<double>(total_);
  }

 private:
  std::string path_;
  rosbag::Bag bag_;
  std::string topic_, type_, definition_;
  std::optional<rosbag::View> view_;
  rosbag::View::iterator next_;
  std::uint64_t total_ = 0, read_ = 0;
};

class Rosbag1Source final : public PacketSource {
 public:
  Rosbag1Source(const std::filesystem::path& path, const std::string& topic)
      : topic_(
            path, topic,
            [](const rosbag::ConnectionInfo& connection) {
              // The layout from the definition the bag stores for the connection.
              return RosEventLayout::of(RosSerialization::Ros1, connection.datatype, connection.msg_def).has_value();
            },
            "an event type", std::string(kKnownEventTypes)),
        layout_(*RosEventLayout::of(RosSerialization::Ros1, topic_.type(), topic_.definition())) {}

  bool next(RecordingPacket& packet) override {
    packet.location = topic_.location();
    try {
      if (!topic_.next(buffer_)) return false;
      const RosEventMessage decoded = layout_.decode(buffer_, scratch_);
      fill_packet(decoded, packet);
      if (camera_.empty()) camera_ = decoded.frame_id;
      return true;
    } catch (const rosbag::BagException& error) {
      throw FormatError(topic_.path(), 0, packet.location + ": " + error.what());
    } catch (const std::runtime_error& error) {
      throw FormatError(topic_.path(), 0, packet.location + ": " + error.what());
    }
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }  // in the messages
  [[nodiscard]] std::string camera() const override { return camera_; }
  [[nodiscard]] std::string description() const override {
    return "ROS 1 bag, " + topic_.topic() + " (" + topic_.type() + ")";
  }
  [[nodiscard]] double progress() const override { return topic_.progress(); }
  [[nodiscard]] std::uint64_t skipped_packets() const override { return 0; }  // other topics are not read

 private:
  Rosbag1Topic topic_;
  RosEventLayout layout_;
  std::string camera_;
  std::vector<std::uint8_t> buffer_, scratch_;
};

class Rosbag1ImageSource final : public ImageSource {
 public:
  Rosbag1ImageSource(const std::filesystem::path& path, const std::string& topic)
      : topic_(
            path, topic, [](const rosbag::ConnectionInfo& connection) { return connection.datatype == kRos1ImageType; },
            "type " + std::string(kRos1ImageType), std::string(kRos1ImageType)) {}

  bool next(RecordingImage& image, std::string& location) override {
    location = topic_.path() + ", " + topic_.location();
    try {
      if (!topic_.next(buffer_)) return false;
      image = decode_ros_image(RosSerialization::Ros1, buffer_);
      return true;
    } catch (const rosbag::BagException& error) {
      throw std::runtime_error(location + ": " + error.what());
    } catch (const std::runtime_error& error) {
      throw std::runtime_error(location + ": " + error.what());
    }
  }

  [[nodiscard]] std::string description() const override {
    return "ROS 1 bag, " + topic_.topic() + " (" + topic_.type() + ")";
  }

 private:
  Rosbag1Topic topic_;
  std::vector<std::uint8_t> buffer_;  // the message the image's data points into
};

}  // namespace

std::unique_ptr<ImageSource> open_rosbag1_images(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<Rosbag1ImageSource>(path, topic);
}

std::unique_ptr<PacketSource> open_rosbag1(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<Rosbag1Source>(path, topic);
}

}  // namespace evldt
