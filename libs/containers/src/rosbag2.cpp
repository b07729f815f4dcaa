#include "evldt/containers/rosbag2.hpp"

#include <sqlite3.h>

#include <functional>
#include <span>
#include <stdexcept>

#include "evldt/containers/ros_messages.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {
namespace {

class Statement {
 public:
  Statement(sqlite3* db, const char* sql) {
    if (sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr) != SQLITE_OK) {
      throw std::runtime_error(sqlite3_errmsg(db));
    }
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  sqlite3_stmt* get() const { return statement_; }

 private:
  sqlite3_stmt* statement_ = nullptr;
};

std::string column_text(sqlite3_stmt* statement, int column) {
  const unsigned char* text = sqlite3_column_text(statement, column);
  return text ? reinterpret_cast<const char*>(text) : "";
}

/// One topic of a bag, read in time order as CDR messages: the topic `wanted`, or if empty the
/// first whose type (and the definition the bag keeps for it, empty where it keeps none) `accepts`.
/// For errors, `kind` names what it looks for ("an event type") and `expected` the types it
/// accepts. Throws std::runtime_error naming the file for a bag it cannot read or no such topic.
class Rosbag2Topic {
 public:
  Rosbag2Topic(const std::filesystem::path& path, const std::string& wanted,
               const std::function<bool(const std::string& type, const std::string& definition)>& accepts,
               const std::string& kind, const std::string& expected)
      : path_(path.string()) {
    if (sqlite3_open_v2(path_.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string reason = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw std::runtime_error("cannot open ROS 2 bag '" + path_ + "': " + reason);
    }
    try {
      choose_topic(wanted, accepts, kind, expected);
      Statement count(db_, "SELECT COUNT(*) FROM messages WHERE topic_id = ?");
      sqlite3_bind_int64(count.get(), 1, topic_id_);
      if (sqlite3_step(count.get()) == SQLITE_ROW)
        total_ = static_cast<std::uint64_t>(sqlite3_column_int64(count.get(), 0));
      // In time order as rosbag2 plays them; the timestamp index makes this a stream, not a sort.
      messages_.emplace(db_, "SELECT id, data FROM messages WHERE topic_id = ? ORDER BY timestamp, id");
      sqlite3_bind_int64(messages_->get(), 1, topic_id_);
    } catch (const std::runtime_error& error) {
      messages_.reset();
      sqlite3_close(db_);
      throw std::runtime_error("'" + path_ + "' is not a readable ROS 2 bag: " + error.what());
    }
  }
  ~Rosbag2Topic() {
    messages_.reset();
    sqlite3_close(db_);
  }
  Rosbag2Topic(const Rosbag2Topic&) = delete;
  Rosbag2Topic& operator=(const Rosbag2Topic&) = delete;

  /// The next message (valid until the next call) and where it is ("message id 17"); false at the
  /// end. Throws FormatError when SQLite cannot read on.
  bool next(std::span<const std::uint8_t>& message, std::string& location) {
    const int status = sqlite3_step(messages_->get());
    if (status == SQLITE_DONE) return false;
    if (status != SQLITE_ROW)
      throw FormatError(path_, 0, std::string("cannot read the next message: ") + sqlite3_errmsg(db_));
    ++read_;
    location = "message id " + std::to_string(sqlite3_column_int64(messages_->get(), 0));
    const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(messages_->get(), 1));
    message = {data, static_cast<std::size_t>(sqlite3_column_bytes(messages_->get(), 1))};
    return true;
  }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] const std::string& topic() const { return topic_; }
  [[nodiscard]] const std::string& type() const { return type_; }
  [[nodiscard]] const std::string& definition() const { return definition_; }
  [[nodiscard]] double progress() const {
    return total_ == 0 ? 1.0 : static_cast<double>(read_) / static_cast<double>(total_);
  }

 private:
  /// The .msg definition of `type` where the bag keeps one (rosbag2 since Iron: message_definitions);
  /// empty otherwise.
  std::string message_definition(const std::string& type) const {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(
            db_,
            "SELECT encoded_message_definition FROM message_definitions WHERE topic_type = ? AND encoding = 'ros2msg'",
            -1, &statement, nullptr) != SQLITE_OK) {
      return {};  // an older bag: no such table
    }
    sqlite3_bind_text(statement, 1, type.c_str(), -1, SQLITE_TRANSIENT);
    std::string definition = sqlite3_step(statement) == SQLITE_ROW ? column_text(statement, 0) : std::string();
    sqlite3_finalize(statement);
    return definition;
  }

  void choose_topic(const std::string& wanted,
                    const std::function<bool(const std::string&, const std::string&)>& accepts, const std::string& kind,
                    const std::string& expected) {
    Statement topics(db_, "SELECT id, name, type FROM topics ORDER BY id");
    std::string listing;
    while (sqlite3_step(topics.get()) == SQLITE_ROW) {
      const std::int64_t id = sqlite3_column_int64(topics.get(), 0);
      const std::string name = column_text(topics.get(), 1), type = column_text(topics.get(), 2);
      listing.append(listing.empty() ? "" : ", ").append(name).append(" (").append(type).append(")");
      if (topic_id_ >= 0 || (!wanted.empty() && name != wanted)) continue;
      std::string definition = message_definition(type);
      if (!accepts(type, definition)) {
        if (wanted.empty()) continue;
        throw std::runtime_error("topic " + name + " is of type " + type + ", not " + expected);
      }
      topic_id_ = id;
      topic_ = name;
      type_ = type;
      definition_ = std::move(definition);
    }
    if (topic_id_ < 0) {
      throw std::runtime_error((wanted.empty() ? "no topic of " + kind : "no topic " + wanted) +
                               " (topics: " + (listing.empty() ? "none" : listing) + ")");
    }
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  std::int64_t topic_id_ = -1;
  std::string topic_, type_, definition_;
  std::uint64_t total_ = 0, read_ = 0;
  std::optional<Statement> messages_;
};

class Rosbag2Source final : public PacketSource {
 public:
  Rosbag2Source(const std::filesystem::path& path, const std::string& topic)
      : topic_(
            path, topic,
            [](const std::string& type, const std::string& definition) {
              return RosEventLayout::of(RosSerialization::Cdr, type, definition).has_value();
            },
            "an event type", std::string(kKnownEventTypes)),
        layout_(*RosEventLayout::of(RosSerialization::Cdr, topic_.type(), topic_.definition())) {}

  bool next(RecordingPacket& packet) override {
    std::span<const std::uint8_t> message;
    if (!topic_.next(message, packet.location)) return false;
    try {
      const RosEventMessage decoded = layout_.decode(message, scratch_);
      fill_packet(decoded, packet);
      if (camera_.empty()) camera_ = decoded.frame_id;
    } catch (const std::runtime_error& error) {
      throw FormatError(topic_.path(), 0, packet.location + " of " + topic_.topic() + ": " + error.what());
    }
    return true;
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }  // in the packets
  [[nodiscard]] std::string camera() const override { return camera_; }
  [[nodiscard]] std::string description() const override {
    return "ROS 2 bag, " + topic_.topic() + " (" + topic_.type() + ")";
  }
  [[nodiscard]] double progress() const override { return topic_.progress(); }
  [[nodiscard]] std::uint64_t skipped_packets() const override { return 0; }  // other topics are not read

 private:
  Rosbag2Topic topic_;
  RosEventLayout layout_;
  std::string camera_;
  std::vector<std::uint8_t> scratch_;
};

class Rosbag2ImageSource final : public ImageSource {
 public:
  Rosbag2ImageSource(const std::filesystem::path& path, const std::string& topic)
      : topic_(
            path, topic, [](const std::string& type, const std::string&) { return type == kRos2ImageType; },
            "type " + std::string(kRos2ImageType), std::string(kRos2ImageType)) {}

  bool next(RecordingImage& image, std::string& location) override {
    std::span<const std::uint8_t> message;
    std::string where;
    if (!topic_.next(message, where)) return false;
    location = topic_.path() + ", " + where + " of " + topic_.topic();
    try {
      image = decode_ros_image(RosSerialization::Cdr, message);
    } catch (const std::runtime_error& error) {
      throw std::runtime_error(location + ": " + error.what());
    }
    return true;
  }

  [[nodiscard]] std::string description() const override {
    return "ROS 2 bag, " + topic_.topic() + " (" + topic_.type() + ")";
  }

 private:
  Rosbag2Topic topic_;
};

}  // namespace

std::unique_ptr<ImageSource> open_rosbag2_images(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<Rosbag2ImageSource>(path, topic);
}

std::unique_ptr<PacketSource> open_rosbag2(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<Rosbag2Source>(path, topic);
}

}  // namespace evldt
