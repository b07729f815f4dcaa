#include "evldt/containers/rosbag1.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <stdexcept>

#include "evldt/containers/ros_messages.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {
namespace {

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
        // The layout from the definition the bag stores for the connection.
        auto layout = RosEventLayout::of(RosSerialization::Ros1, connection->datatype, connection->msg_def);
        if (topic.empty() ? layout.has_value() : connection->topic == topic) {
          if (!layout) {
            throw std::runtime_error("topic " + topic + " is of type " + connection->datatype + ", not " +
                                     std::string(kKnownEventTypes));
          }
          topic_ = connection->topic;
          type_ = connection->datatype;
          layout_ = std::move(layout);
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
      const RosEventMessage decoded = layout_->decode(buffer_, scratch_);
      fill_packet(decoded, packet);
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
  std::optional<RosEventLayout> layout_;
  std::optional<rosbag::View> view_;
  rosbag::View::iterator next_;
  std::uint64_t total_ = 0, read_ = 0;
  std::vector<std::uint8_t> buffer_, scratch_;
};

class Rosbag1ImageSource final : public ImageSource {
 public:
  Rosbag1ImageSource(const std::filesystem::path& path, const std::string& topic) : path_(path.string()) {
    try {
      bag_.open(path_, rosbag::bagmode::Read);
      rosbag::View all(bag_);
      std::string listing;
      for (const rosbag::ConnectionInfo* connection : all.getConnections()) {
        listing += (listing.empty() ? "" : ", ") + connection->topic + " (" + connection->datatype + ")";
        if (!topic_.empty() || (topic.empty() ? connection->datatype != kRos1ImageType : connection->topic != topic)) continue;
        if (connection->datatype != kRos1ImageType) {
          throw std::runtime_error("topic " + topic + " is of type " + connection->datatype + ", not " + std::string(kRos1ImageType));
        }
        topic_ = connection->topic;
      }
      if (topic_.empty()) {
        throw std::runtime_error((topic.empty() ? "no topic of type " + std::string(kRos1ImageType) : "no topic " + topic) +
                                 " (topics: " + (listing.empty() ? "none" : listing) + ")");
      }
      view_.emplace(bag_, rosbag::TopicQuery(topic_));
      next_ = view_->begin();
    } catch (const rosbag::BagException& error) {
      throw std::runtime_error("'" + path_ + "' is not a readable ROS 1 bag: " + error.what());
    } catch (const std::runtime_error& error) {
      throw std::runtime_error("'" + path_ + "': " + error.what());
    }
  }

  bool next(RecordingImage& image, std::string& location) override {
    location = path_ + ", message " + std::to_string(read_) + " of " + topic_;
    try {
      if (next_ == view_->end()) return false;
      const rosbag::MessageInstance& message = *next_;
      buffer_.resize(message.size());
      ros::serialization::OStream stream(buffer_.data(), static_cast<std::uint32_t>(buffer_.size()));
      message.write(stream);
      image = decode_ros_image(RosSerialization::Ros1, buffer_);
      ++read_;
      ++next_;
      return true;
    } catch (const rosbag::BagException& error) {
      throw std::runtime_error(location + ": " + error.what());
    } catch (const std::runtime_error& error) {
      throw std::runtime_error(location + ": " + error.what());
    }
  }

  [[nodiscard]] std::string description() const override { return "ROS 1 bag, " + topic_ + " (" + std::string(kRos1ImageType) + ")"; }

 private:
  std::string path_;
  rosbag::Bag bag_;
  std::string topic_;
  std::optional<rosbag::View> view_;
  rosbag::View::iterator next_;
  std::uint64_t read_ = 0;
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
