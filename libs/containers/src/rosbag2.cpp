#include "evldt/containers/rosbag2.hpp"

#include <sqlite3.h>

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

class Rosbag2Source final : public PacketSource {
 public:
  Rosbag2Source(const std::filesystem::path& path, const std::string& topic) : path_(path.string()) {
    if (sqlite3_open_v2(path_.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string reason = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw std::runtime_error("cannot open ROS 2 bag '" + path_ + "': " + reason);
    }
    try {
      choose_topic(topic);
      Statement count(db_, "SELECT COUNT(*) FROM messages WHERE topic_id = ?");
      sqlite3_bind_int64(count.get(), 1, topic_id_);
      if (sqlite3_step(count.get()) == SQLITE_ROW) total_ = static_cast<std::uint64_t>(sqlite3_column_int64(count.get(), 0));
      // In time order as rosbag2 plays them; the timestamp index makes this a stream, not a sort.
      messages_.emplace(db_, "SELECT id, data FROM messages WHERE topic_id = ? ORDER BY timestamp, id");
      sqlite3_bind_int64(messages_->get(), 1, topic_id_);
    } catch (const std::runtime_error& error) {
      messages_.reset();
      sqlite3_close(db_);
      throw std::runtime_error("'" + path_ + "' is not a readable ROS 2 bag: " + error.what());
    }
  }
  ~Rosbag2Source() override {
    messages_.reset();
    sqlite3_close(db_);
  }

  bool next(RecordingPacket& packet) override {
    const int status = sqlite3_step(messages_->get());
    if (status == SQLITE_DONE) return false;
    if (status != SQLITE_ROW) throw FormatError(path_, 0, std::string("cannot read the next message: ") + sqlite3_errmsg(db_));
    ++read_;
    const std::int64_t id = sqlite3_column_int64(messages_->get(), 0);
    const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(messages_->get(), 1));
    const auto size = static_cast<std::size_t>(sqlite3_column_bytes(messages_->get(), 1));
    packet.location = "message id " + std::to_string(id);
    try {
      const RosEventMessage message = layout_->decode({data, size}, scratch_);
      fill_packet(message, packet);
      if (camera_.empty()) camera_ = message.frame_id;
    } catch (const std::runtime_error& error) {
      throw FormatError(path_, 0, packet.location + " of " + topic_ + ": " + error.what());
    }
    return true;
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }  // in the packets
  [[nodiscard]] std::string camera() const override { return camera_; }
  [[nodiscard]] std::string description() const override { return "ROS 2 bag, " + topic_ + " (" + type_ + ")"; }
  [[nodiscard]] double progress() const override {
    return total_ == 0 ? 1.0 : static_cast<double>(read_) / static_cast<double>(total_);
  }
  [[nodiscard]] std::uint64_t skipped_packets() const override { return 0; }  // other topics are not read

 private:
  /// The .msg definition of `type` where the bag keeps one (rosbag2 since Iron: message_definitions);
  /// empty otherwise.
  std::string message_definition(const std::string& type) const {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, "SELECT encoded_message_definition FROM message_definitions WHERE topic_type = ? AND encoding = 'ros2msg'",
                           -1, &statement, nullptr) != SQLITE_OK) {
      return {};  // an older bag: no such table
    }
    sqlite3_bind_text(statement, 1, type.c_str(), -1, SQLITE_TRANSIENT);
    std::string definition = sqlite3_step(statement) == SQLITE_ROW ? column_text(statement, 0) : std::string();
    sqlite3_finalize(statement);
    return definition;
  }

  void choose_topic(const std::string& wanted) {
    Statement topics(db_, "SELECT id, name, type FROM topics ORDER BY id");
    std::string listing;
    while (sqlite3_step(topics.get()) == SQLITE_ROW) {
      const std::int64_t id = sqlite3_column_int64(topics.get(), 0);
      const std::string name = column_text(topics.get(), 1), type = column_text(topics.get(), 2);
      listing += (listing.empty() ? "" : ", ") + name + " (" + type + ")";
      if (topic_id_ >= 0) continue;
      auto layout = RosEventLayout::of(RosSerialization::Cdr, type, message_definition(type));
      if (wanted.empty() ? layout.has_value() : name == wanted) {
        if (!layout) {
          throw std::runtime_error("topic " + name + " is of type " + type + ", not " + std::string(kKnownEventTypes));
        }
        topic_id_ = id;
        topic_ = name;
        type_ = type;
        layout_ = std::move(layout);
      }
    }
    if (topic_id_ < 0) {
      throw std::runtime_error((wanted.empty() ? std::string("no topic of an event type") : "no topic " + wanted) +
                               " (topics: " + (listing.empty() ? "none" : listing) + ")");
    }
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  std::int64_t topic_id_ = -1;
  std::string topic_, type_;
  std::optional<RosEventLayout> layout_;
  std::string camera_;
  std::vector<std::uint8_t> scratch_;
  std::uint64_t total_ = 0, read_ = 0;
  std::optional<Statement> messages_;
};

}  // namespace

std::unique_ptr<PacketSource> open_rosbag2(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<Rosbag2Source>(path, topic);
}

}  // namespace evldt
