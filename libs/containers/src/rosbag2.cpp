#include "evldt/containers/rosbag2.hpp"

#include <sqlite3.h>

#include <bit>
#include <cstring>
#include <stdexcept>

#include "evldt/events/event_format.hpp"

namespace evldt {
namespace {

// CDR (OMG XCDR1, as ROS 2 writes it): a 4-byte encapsulation header (0x00 0x01 little-endian,
// 0x00 0x00 big-endian, then two option bytes), then each primitive aligned to its own size,
// counted from after that header; a string is a uint32 length counting its NUL, then the bytes;
// a sequence is a uint32 count, then the elements.
class CdrReader {
 public:
  explicit CdrReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {
    if (bytes.size() < 4 || bytes[0] != 0 || bytes[1] > 1) fail("no CDR encapsulation header");
    little_endian_ = bytes[1] == 1;
    body_ = 4;
    at_ = 4;
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
    if (length == 0) fail("string without its NUL");
    need(length);
    if (bytes_[at_ + length - 1] != 0) fail("string not terminated");
    std::string text(reinterpret_cast<const char*>(bytes_.data() + at_), length - 1);
    at_ += length;
    return text;
  }
  std::span<const std::uint8_t> read_bytes() {
    const auto count = read<std::uint32_t>();
    need(count);
    const auto out = bytes_.subspan(at_, count);
    at_ += count;
    return out;
  }

 private:
  template <typename T>
  static T byteswap(T value) {
    if constexpr (sizeof(T) == 1) {
      return value;
    } else {
      std::uint8_t raw[sizeof(T)];
      std::memcpy(raw, &value, sizeof(T));
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
      std::memcpy(&value, raw, sizeof(T));
      return value;
    }
  }
  void align(std::size_t size) {
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
    throw std::runtime_error("CDR byte " + std::to_string(at_) + ": " + reason);
  }

  std::span<const std::uint8_t> bytes_;
  bool little_endian_ = true;
  std::size_t body_ = 0;
  std::size_t at_ = 0;
};

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
    EventPacketMessage message;
    try {
      message = decode_event_packet_cdr({data, size});
    } catch (const std::runtime_error& error) {
      throw FormatError(path_, 0, packet.location + " of " + topic_ + ": " + error.what());
    }
    if (message.is_bigendian) throw FormatError(path_, 0, packet.location + ": big-endian event data is not supported");
    packet.bytes.assign(message.events.begin(), message.events.end());
    packet.encoding = message.encoding;
    packet.time_base_ns = static_cast<std::int64_t>(message.time_base);
    packet.sensor = sensor_of(message.width, message.height);
    if (camera_.empty()) camera_ = message.frame_id;
    return true;
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }  // in the packets
  [[nodiscard]] std::string camera() const override { return camera_; }
  [[nodiscard]] std::string description() const override { return "ROS 2 bag, " + topic_ + " (" + kEventPacketType + ")"; }
  [[nodiscard]] double progress() const override {
    return total_ == 0 ? 1.0 : static_cast<double>(read_) / static_cast<double>(total_);
  }
  [[nodiscard]] std::uint64_t skipped_packets() const override { return 0; }  // other topics are not read

 private:
  void choose_topic(const std::string& wanted) {
    Statement topics(db_, "SELECT id, name, type FROM topics ORDER BY id");
    std::string listing;
    while (sqlite3_step(topics.get()) == SQLITE_ROW) {
      const std::int64_t id = sqlite3_column_int64(topics.get(), 0);
      const std::string name = column_text(topics.get(), 1), type = column_text(topics.get(), 2);
      listing += (listing.empty() ? "" : ", ") + name + " (" + type + ")";
      if (topic_id_ >= 0) continue;
      if (wanted.empty() ? type == kEventPacketType : name == wanted) {
        if (type != kEventPacketType) {
          throw std::runtime_error("topic " + name + " is of type " + type + ", not " + kEventPacketType);
        }
        topic_id_ = id;
        topic_ = name;
      }
    }
    if (topic_id_ < 0) {
      throw std::runtime_error((wanted.empty() ? std::string("no topic of type ") + kEventPacketType : "no topic " + wanted) +
                               " (topics: " + (listing.empty() ? "none" : listing) + ")");
    }
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  std::int64_t topic_id_ = -1;
  std::string topic_;
  std::string camera_;
  std::uint64_t total_ = 0, read_ = 0;
  std::optional<Statement> messages_;
};

}  // namespace

EventPacketMessage decode_event_packet_cdr(std::span<const std::uint8_t> cdr) {
  CdrReader reader(cdr);
  EventPacketMessage message;
  reader.read<std::int32_t>();   // header.stamp.sec
  reader.read<std::uint32_t>();  // header.stamp.nanosec
  message.frame_id = reader.read_string();
  message.height = reader.read<std::uint32_t>();
  message.width = reader.read<std::uint32_t>();
  message.seq = reader.read<std::uint64_t>();
  message.time_base = reader.read<std::uint64_t>();
  message.encoding = reader.read_string();
  message.is_bigendian = reader.read<std::uint8_t>() != 0;
  message.events = reader.read_bytes();
  return message;
}

std::unique_ptr<PacketSource> open_rosbag2(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<Rosbag2Source>(path, topic);
}

}  // namespace evldt
