#pragma once
// Writes MCAP files (specification major version 0): schemas, channels and messages in one
// unchunked data section, then the data end and the footer, without a summary (readers such as
// Foxglove read such a file from the start). What evldt-export writes its Foxglove messages into.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <string_view>

namespace evldt {

class McapWriter {
 public:
  /// Creates `path` and writes the magic and the header (`profile`: "" or e.g. "ros2"). Throws
  /// std::runtime_error naming the file if it cannot be created.
  McapWriter(const std::filesystem::path& path, const std::string& profile = "");
  /// Finishes the file if close() was not called (errors then are only logged).
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// A schema (e.g. name "foxglove.CompressedImage", encoding "jsonschema", data its JSON Schema);
  /// returns its id (from 1).
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, std::string_view data);
  /// A channel of messages of a schema (0: none) in `message_encoding` (e.g. "json"); returns its id.
  std::uint16_t add_channel(std::uint16_t schema, const std::string& topic, const std::string& message_encoding);
  /// A message on a channel, logged and published at `time_ns` (ns since the epoch, or since the
  /// recording's start); numbered per channel.
  void write(std::uint16_t channel, std::uint64_t time_ns, std::string_view data);
  /// Writes the data end, the footer and the closing magic, and closes the file. Throws
  /// std::runtime_error naming the file if it could not be written.
  void close();

  [[nodiscard]] std::uint64_t messages() const { return messages_; }

 private:
  void record(std::uint8_t opcode, const std::string& content);

  std::filesystem::path path_;
  std::ofstream out_;
  bool closed_ = false;
  std::uint16_t schemas_ = 0, channels_ = 0;
  std::map<std::uint16_t, std::uint32_t> sequence_;
  std::uint64_t messages_ = 0;
  std::string scratch_;
};

}  // namespace evldt
