#pragma once
// Fixtures of ROS 2 bags, written from the format descriptions: CDR as ROS 2 serializes messages,
// and SQLite bags with the tables rosbag2 (schema 3) writes.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace evldt::test_support {

/// Writes CDR as ROS 2 does: the encapsulation header, then every primitive aligned to its size.
class CdrWriter {
 public:
  explicit CdrWriter(bool little_endian) : little_endian_(little_endian) {
    bytes_ = {0x00, static_cast<std::uint8_t>(little_endian ? 0x01 : 0x00), 0x00, 0x00};
  }
  template <typename T>
  void put(T value) {
    while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0);
    std::uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (little_endian_ != (std::endian::native == std::endian::little)) std::reverse(raw, raw + sizeof(T));
    bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
  }
  void put_string(const std::string& text) {
    put(static_cast<std::uint32_t>(text.size() + 1));
    bytes_.insert(bytes_.end(), text.begin(), text.end());
    bytes_.push_back(0);
  }
  void put_bytes(const std::vector<std::uint8_t>& data) {
    put(static_cast<std::uint32_t>(data.size()));
    bytes_.insert(bytes_.end(), data.begin(), data.end());
  }
  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  bool little_endian_;
  std::vector<std::uint8_t> bytes_;
};

/// A ROS 2 bag in SQLite storage with the tables rosbag2 (schema 3) writes.
class BagWriter {
 public:
  explicit BagWriter(const std::filesystem::path& path) {
    std::filesystem::remove(path);
    EXPECT_EQ(sqlite3_open(path.c_str(), &db_), SQLITE_OK);
    exec(
        "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
        " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data "
        "BLOB NOT NULL);"
        "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
        "INSERT INTO schema VALUES (3, 'humble');");
  }
  ~BagWriter() { sqlite3_close(db_); }
  void topic(int id, const std::string& name, const std::string& type) {
    exec("INSERT INTO topics VALUES (" + std::to_string(id) + ", '" + name + "', '" + type + "', 'cdr', '')");
  }
  /// The definition of a type, as rosbag2 keeps them since Iron (table message_definitions).
  void definition(const std::string& type, const std::string& text) {
    exec(
        "CREATE TABLE IF NOT EXISTS message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL,"
        " encoding TEXT NOT NULL, encoded_message_definition TEXT NOT NULL, type_description_hash TEXT NOT NULL);");
    exec(
        "INSERT INTO message_definitions (topic_type, encoding, encoded_message_definition, type_description_hash) "
        "VALUES ('" +
        type + "', 'ros2msg', '" + text + "', '')");
  }
  void message(int topic_id, std::int64_t timestamp, const std::vector<std::uint8_t>& data) {
    sqlite3_stmt* statement = nullptr;
    sqlite3_prepare_v2(db_, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1, &statement,
                       nullptr);
    sqlite3_bind_int(statement, 1, topic_id);
    sqlite3_bind_int64(statement, 2, timestamp);
    sqlite3_bind_blob(statement, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE);
    sqlite3_finalize(statement);
  }

 private:
  void exec(const std::string& sql) {
    EXPECT_EQ(sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql;
  }
  sqlite3* db_ = nullptr;
};

}  // namespace evldt::test_support
