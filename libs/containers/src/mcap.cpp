#include "evldt/containers/mcap.hpp"

#include <zlib.h>

#include <functional>
#include <map>
#include <stdexcept>
#include <vector>

#include "container_file.hpp"
#include "decompress.hpp"
#include "evldt/containers/ros_messages.hpp"
#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_format.hpp"
#include "mcap_records.hpp"

namespace evldt {
namespace {

/// Fields of a record's content: little-endian integers, strings and byte arrays with a length prefix.
class FieldReader {
 public:
  explicit FieldReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  template <typename T>
  T read() {
    const auto raw = take(sizeof(T));
    std::uint64_t value = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) value |= std::uint64_t{raw[i]} << (8 * i);
    return static_cast<T>(value);
  }
  std::string read_string() {
    const auto text = take(read<std::uint32_t>());
    return {reinterpret_cast<const char*>(text.data()), text.size()};
  }
  std::span<const std::uint8_t> take(std::uint64_t count) {
    if (count > bytes_.size() - at_) throw std::runtime_error("record ends inside a field");
    const auto out = bytes_.subspan(at_, count);
    at_ += count;
    return out;
  }
  [[nodiscard]] std::span<const std::uint8_t> rest() const { return bytes_.subspan(at_); }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

struct Record {
  std::uint8_t opcode = 0;
  std::span<const std::uint8_t> content;
  std::uint64_t offset = 0;  ///< in the file: the record's, or its chunk's
  bool in_chunk = false;
};

struct Channel {
  std::string topic, type, encoding;
  std::string definition;                    // the schema's data: the .msg text of a ros1msg / ros2msg schema
  std::string schema_encoding, schema_data;  // of any schema
};

/// A channel in a ROS serialization, and which.
bool ros_serialized(const Channel& channel) { return channel.encoding == "ros1" || channel.encoding == "cdr"; }
RosSerialization ros_serialization(const Channel& channel) {
  return channel.encoding == "ros1" ? RosSerialization::Ros1 : RosSerialization::Cdr;
}

struct Schema {
  std::string name;
  std::string definition;
  std::string encoding, data;
};

/// One channel of an MCAP file, its messages read in file order: the channel `wanted`, or if empty
/// the first that `accepts` (given its type, serialization and schema definition; channels in
/// neither ROS serialization are never accepted). For errors,
/// `kind` names what it looks for ("an event type") and `expected` the types it accepts. Throws
/// std::runtime_error naming the file for a file it cannot read or no such channel.
class McapChannel {
 public:
  /// Whether a channel is one to read.
  using Accepts = std::function<bool(const Channel& channel)>;
  McapChannel(const std::filesystem::path& path, const std::string& topic, Accepts accepts, std::string kind,
              std::string expected)
      : file_(path, "MCAP"),
        path_(file_.path()),
        wanted_(topic),
        accepts_(std::move(accepts)),
        kind_(std::move(kind)),
        expected_(std::move(expected)) {
    std::string magic(kMcapMagic.size(), '\0');
    file_.read_exactly(magic.data(), magic.size(), "the magic");
    if (magic != kMcapMagic) throw FormatError(path_, 0, "not an MCAP file");
    // A channel is described before its first message: read on until the one to use.
    Record record;
    while (channel_id_ < 0 && next_record(record)) handle(record);
    if (channel_id_ < 0) {
      std::string listing;
      for (const auto& entry : channels_) {
        listing += (listing.empty() ? "" : ", ") + entry.second.topic + " (" + entry.second.type + ", " +
                   entry.second.encoding + ")";
      }
      throw std::runtime_error("'" + path_ +
                               "': " + (wanted_.empty() ? "no channel of " + kind_ : "no channel " + wanted_) +
                               " (channels: " + (listing.empty() ? "none" : listing) + ")");
    }
  }

  /// The next message's payload (valid until the next call) and where it is; false at the end.
  /// Throws FormatError for a file that cannot be read on.
  bool next(std::span<const std::uint8_t>& message, std::string& location, std::uint64_t& offset) {
    Record record;
    while (next_record(record)) {
      if (!handle(record)) continue;
      location = "message " + std::to_string(read_) + " of " + channel_.topic + " (record at byte " +
                 std::to_string(record.offset) + ")";
      offset = record.offset;
      try {
        FieldReader fields(record.content);
        fields.take(2 + 4);  // channel id, sequence
        log_time_ns_ = fields.read<std::uint64_t>();
        fields.take(8);  // publish time
        message = fields.rest();
      } catch (const std::runtime_error& error) {
        throw FormatError(path_, record.offset, location + ": " + error.what());
      }
      ++read_;
      return true;
    }
    return false;
  }

  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] const Channel& channel() const { return channel_; }
  [[nodiscard]] const std::string& topic() const { return channel_.topic; }
  [[nodiscard]] const std::string& type() const { return channel_.type; }
  [[nodiscard]] const std::string& definition() const { return channel_.definition; }
  [[nodiscard]] RosSerialization serialization() const { return ros_serialization(channel_); }
  [[nodiscard]] double progress() const {
    return file_.size() == 0 ? 1.0 : static_cast<double>(file_.position()) / static_cast<double>(file_.size());
  }
  [[nodiscard]] std::uint64_t skipped() const { return skipped_; }
  /// Of the message next() returned last.
  [[nodiscard]] std::uint64_t log_time_ns() const { return log_time_ns_; }

 private:
  /// The next record of the data section, from the current chunk or the file; false at its end.
  bool next_record(Record& record) {
    if (chunk_at_ < chunk_.size()) {
      FieldReader header{std::span<const std::uint8_t>(chunk_).subspan(chunk_at_)};
      try {
        record.opcode = header.read<std::uint8_t>();
        record.content = header.take(header.read<std::uint64_t>());
      } catch (const std::runtime_error&) {
        throw FormatError(path_, chunk_offset_,
                          "a record inside the chunk at byte " + std::to_string(chunk_offset_) + " runs past its end");
      }
      record.offset = chunk_offset_;
      record.in_chunk = true;
      chunk_at_ += 9 + record.content.size();
      return true;
    }
    if (at_end_) return false;
    std::uint8_t header[9];
    record.offset = file_.position();
    if (file_.position() == file_.size())
      throw FormatError(path_, file_.position(), "file ends without its footer (a recording cut short)");
    file_.read_exactly(header, sizeof header, "a record header");
    FieldReader fields{std::span<const std::uint8_t>(header)};
    record.opcode = fields.read<std::uint8_t>();
    const auto length = fields.read<std::uint64_t>();
    if (length > file_.size() - file_.position() || length > detail::kMaxDecompressedBytes) {
      throw FormatError(
          path_, record.offset,
          "record of " + std::to_string(length) + " bytes does not fit in the file (a recording cut short?)");
    }
    file_record_.resize(length);
    file_.read_exactly(file_record_.data(), length, "a record");
    record.content = file_record_;
    record.in_chunk = false;
    if (record.opcode == detail::kMcapDataEnd || record.opcode == detail::kMcapFooter) {
      at_end_ = true;  // the summary after it repeats schemas and channels, and has no messages
      return false;
    }
    return true;
  }

  /// Takes in a record: schemas, channels, chunks. True for a message of the chosen channel.
  bool handle(const Record& record) {
    try {
      FieldReader fields(record.content);
      switch (record.opcode) {
        case detail::kMcapSchema: {
          const auto id = fields.read<std::uint16_t>();
          Schema& schema = schemas_[id];
          schema.name = fields.read_string();
          schema.encoding = fields.read_string();
          schema.data = fields.read_string();  // uint32-prefixed bytes, as a string is
          schema.definition =
              schema.encoding == "ros1msg" || schema.encoding == "ros2msg" ? schema.data : std::string();
          return false;
        }
        case detail::kMcapChannel: {
          const auto id = fields.read<std::uint16_t>();
          const auto schema = fields.read<std::uint16_t>();
          Channel channel;
          channel.topic = fields.read_string();
          channel.encoding = fields.read_string();
          const auto found = schemas_.find(schema);
          channel.type = found == schemas_.end() ? "no schema" : found->second.name;
          if (found != schemas_.end()) {
            channel.definition = found->second.definition;
            channel.schema_encoding = found->second.encoding;
            channel.schema_data = found->second.data;
          }
          consider(id, channel);
          channels_[id] = std::move(channel);
          return false;
        }
        case detail::kMcapMessage: {
          if (fields.read<std::uint16_t>() == channel_id_ && channel_id_ >= 0) return true;
          ++skipped_;
          return false;
        }
        case detail::kMcapChunk:
          if (record.in_chunk) throw std::runtime_error("a chunk inside a chunk");
          open_chunk(fields, record.offset);
          return false;
        default:
          return false;
      }
    } catch (const FormatError&) {
      throw;
    } catch (const std::runtime_error& error) {
      throw FormatError(path_, record.offset,
                        "record type " + std::to_string(record.opcode) + " at byte " + std::to_string(record.offset) +
                            ": " + error.what());
    }
  }

  void consider(std::uint16_t id, const Channel& channel) {
    if (channel_id_ >= 0 || (!wanted_.empty() && channel.topic != wanted_)) return;
    if (!accepts_(channel)) {
      if (wanted_.empty()) return;
      throw std::runtime_error("'" + path_ + "': channel " + channel.topic + " is of type " + channel.type + " (" +
                               channel.encoding + "), not " + expected_);
    }
    channel_id_ = id;
    channel_ = channel;
  }

  void open_chunk(FieldReader& fields, std::uint64_t offset) {
    fields.take(8 + 8);  // message start and end time
    const auto size = fields.read<std::uint64_t>();
    const auto crc = fields.read<std::uint32_t>();
    const std::string compression = fields.read_string();
    const auto records = fields.take(fields.read<std::uint64_t>());
    if (compression.empty()) {
      chunk_.assign(records.begin(), records.end());
    } else if (compression == "lz4") {
      detail::decompress_lz4_frame(records, chunk_);
    } else if (compression == "zstd") {
      detail::decompress_zstd_frame(records, chunk_);
    } else {
      throw std::runtime_error("unknown chunk compression '" + compression + "'");
    }
    if (chunk_.size() != size) {
      throw std::runtime_error("chunk holds " + std::to_string(chunk_.size()) + " bytes, its header says " +
                               std::to_string(size));
    }
    if (crc != 0 && crc32(0, chunk_.data(), static_cast<uInt>(chunk_.size())) != crc) {
      throw std::runtime_error("chunk CRC mismatch (a corrupt file)");
    }
    chunk_at_ = 0;
    chunk_offset_ = offset;
  }

  detail::ContainerFile file_;
  std::string path_;
  std::string wanted_;
  bool at_end_ = false;
  std::vector<std::uint8_t> file_record_;
  std::vector<std::uint8_t> chunk_;
  std::size_t chunk_at_ = 0;
  std::uint64_t chunk_offset_ = 0;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  int channel_id_ = -1;
  Accepts accepts_;
  std::string kind_, expected_;
  Channel channel_;  // the one read
  std::uint64_t read_ = 0, skipped_ = 0;
  std::uint64_t log_time_ns_ = 0;
};

class McapSource final : public PacketSource {
 public:
  McapSource(const std::filesystem::path& path, const std::string& topic)
      : channel_(
            path, topic,
            [](const Channel& channel) {
              return ros_serialized(channel) &&
                     RosEventLayout::of(ros_serialization(channel), channel.type, channel.definition).has_value();
            },
            "an event type", "an event type evldt reads"),
        layout_(*RosEventLayout::of(channel_.serialization(), channel_.type(), channel_.definition())) {}

  bool next(RecordingPacket& packet) override {
    std::span<const std::uint8_t> message;
    std::uint64_t offset = 0;
    if (!channel_.next(message, packet.location, offset)) return false;
    try {
      const RosEventMessage decoded = layout_.decode(message, scratch_);
      fill_packet(decoded, packet);
      if (camera_.empty()) camera_ = decoded.frame_id;
    } catch (const std::runtime_error& error) {
      throw FormatError(channel_.path(), offset, packet.location + ": " + error.what());
    }
    return true;
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }  // in the messages
  [[nodiscard]] std::string camera() const override { return camera_; }
  [[nodiscard]] std::string description() const override {
    return "MCAP, " + channel_.topic() + " (" + channel_.type() + ")";
  }
  [[nodiscard]] double progress() const override { return channel_.progress(); }
  [[nodiscard]] std::uint64_t skipped_packets() const override { return channel_.skipped(); }

 private:
  McapChannel channel_;
  RosEventLayout layout_;
  std::string camera_;
  std::vector<std::uint8_t> scratch_;
};

class McapImageSource final : public ImageSource {
 public:
  McapImageSource(const std::filesystem::path& path, const std::string& topic)
      : channel_(
            path, topic,
            [](const Channel& channel) {
              return ros_serialized(channel) && (channel.type == kRos2ImageType || channel.type == kRos1ImageType);
            },
            "type " + std::string(kRos2ImageType), std::string(kRos2ImageType)) {}

  bool next(RecordingImage& image, std::string& location) override {
    std::span<const std::uint8_t> message;
    std::uint64_t offset = 0;
    try {
      if (!channel_.next(message, location, offset)) return false;
      location = channel_.path() + ", " + location;
      image = decode_ros_image(channel_.serialization(), message);
    } catch (const FormatError& error) {
      throw std::runtime_error(error.what());
    } catch (const std::runtime_error& error) {
      throw std::runtime_error(location + ": " + error.what());
    }
    return true;
  }

  [[nodiscard]] std::string description() const override {
    return "MCAP, " + channel_.topic() + " (" + channel_.type() + ")";
  }

 private:
  McapChannel channel_;
};

}  // namespace

std::unique_ptr<PacketSource> open_mcap(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<McapSource>(path, topic);
}

std::unique_ptr<ImageSource> open_mcap_images(const std::filesystem::path& path, const std::string& topic) {
  return std::make_unique<McapImageSource>(path, topic);
}

McapChannelMessages read_mcap_channel(const std::filesystem::path& path, const std::string& topic) {
  McapChannel reader(
      path, topic, [](const Channel&) { return true; }, "any type", "any type");
  McapChannelMessages out;
  const Channel& channel = reader.channel();
  out.topic = channel.topic;
  out.schema_name = channel.type;
  out.schema_encoding = channel.schema_encoding;
  out.schema = channel.schema_data;
  out.message_encoding = channel.encoding;
  std::span<const std::uint8_t> message;
  std::string location;
  std::uint64_t offset = 0;
  while (reader.next(message, location, offset)) {
    out.messages.push_back(
        {reader.log_time_ns(), std::string(reinterpret_cast<const char*>(message.data()), message.size())});
  }
  return out;
}

}  // namespace evldt
