#pragma once
// Containers of event recordings (ROS 1 and 2 bags, MCAP, AEDAT 4 files) kept apart from the encodings of their
// events: a container yields packets with their metadata, and the decoder that the packet's encoding
// names (libs/events, make_packet_decoder) turns them into events.

#include <cstdint>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/events/event_decoder.hpp"

namespace evldt {

/// One packet of encoded events as a container stores it.
struct RecordingPacket {
  std::vector<std::uint8_t> bytes;   ///< the encoded events
  std::string encoding;              ///< e.g. "evt3", "libcaer": the decoder to use
  std::int64_t time_base_ns = 0;     ///< for encodings that count time from the packet
  std::optional<SensorSize> sensor;  ///< when the packet says
  std::string location;              ///< where the packet is, for errors: "byte 1234", "message 17"
};

/// A message's width and height as a sensor size, if they make one (a valid size, kMaxSensorSide at most).
std::optional<SensorSize> sensor_of(std::uint32_t width, std::uint32_t height);

class PacketSource {
 public:
  virtual ~PacketSource() = default;
  /// The next packet of the chosen stream; false at the end. Throws FormatError (naming the file and
  /// where) on a container that cannot be read on, after every packet before it.
  virtual bool next(RecordingPacket& packet) = 0;
  /// The sensor size from the container's own metadata, if it has any before the first packet.
  [[nodiscard]] virtual std::optional<SensorSize> geometry() const = 0;
  /// The camera's name or serial, if the container records one.
  [[nodiscard]] virtual std::string camera() const = 0;
  /// What the container is and which stream is read, e.g. "ROS 2 bag, /events (event_camera_msgs/msg/EventPacket)".
  [[nodiscard]] virtual std::string description() const = 0;
  /// Fraction of the packets (or bytes) read, in [0, 1].
  [[nodiscard]] virtual double progress() const = 0;
  /// Packets the container skipped (other streams, types it does not decode).
  [[nodiscard]] virtual std::uint64_t skipped_packets() const = 0;
};

/// Events from a container: each packet through the decoder of its encoding (one decoder per
/// encoding, kept across packets, since a stream's state carries over). Throws FormatError for an
/// encoding no decoder knows, or a packet that cannot be decoded, after the events before it.
class PacketEventReader {
 public:
  PacketEventReader(std::unique_ptr<PacketSource> source, std::string source_name);
  /// Clears `out` and fills it with the events of the next packet(s); false at the end. After a
  /// fault it first returns the events decoded before it, throws on the next call, then returns false.
  bool read(EventBatch& out);
  /// The container's metadata, else the first packet's sensor size.
  [[nodiscard]] std::optional<SensorSize> geometry();
  [[nodiscard]] const PacketSource& source() const { return *source_; }
  [[nodiscard]] DecodeCounts counts() const;

 private:
  bool fill(EventBatch& out);
  bool next_packet();
  /// Ends the current decoder's stream (its last events into `out`), keeping its counts.
  void retire_decoder(EventBatch& out);

  std::unique_ptr<PacketSource> source_;
  std::string source_name_;
  RecordingPacket packet_;
  bool packet_pending_ = false;  // read to learn the sensor size, not decoded yet
  bool at_end_ = false;
  bool failed_ = false;
  std::exception_ptr pending_error_;
  std::string encoding_;
  std::unique_ptr<EventDecoder> decoder_;
  DecodeCounts retired_counts_;
  std::optional<SensorSize> first_packet_sensor_;
};

/// The container `path` holds, recognised by its first bytes (SQLite for a ROS 2 bag, "#ROSBAG V2.0"
/// for a ROS 1 bag, "\x89MCAP0" for MCAP, "#!AER-DAT4.0" for AEDAT 4), or nullptr for a file that is none. `topic`
/// picks a bag's topic (empty: the first with an event message type). Throws std::runtime_error / FormatError for a
/// container it cannot use.
std::unique_ptr<PacketSource> open_packet_container(const std::filesystem::path& path, const std::string& topic);

}  // namespace evldt
