#include "evldt/containers/packet_source.hpp"

#include <cstring>
#include <utility>

#include "container_file.hpp"
#include "evldt/containers/aedat4.hpp"
#include "evldt/containers/mcap.hpp"
#include "evldt/containers/rosbag1.hpp"
#include "evldt/containers/rosbag2.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {

std::optional<SensorSize> sensor_of(std::uint32_t width, std::uint32_t height) {
  if (width > static_cast<std::uint32_t>(kMaxSensorSide) || height > static_cast<std::uint32_t>(kMaxSensorSide))
    return std::nullopt;
  const SensorSize sensor{static_cast<int>(width), static_cast<int>(height)};
  return sensor.valid() ? std::optional(sensor) : std::nullopt;
}

PacketEventReader::PacketEventReader(std::unique_ptr<PacketSource> source, std::string source_name)
    : source_(std::move(source)), source_name_(std::move(source_name)) {}

bool PacketEventReader::next_packet() {
  if (packet_pending_) {
    packet_pending_ = false;
    return true;
  }
  if (at_end_ || !source_->next(packet_)) {
    at_end_ = true;
    return false;
  }
  if (!first_packet_sensor_) first_packet_sensor_ = packet_.sensor;
  return true;
}

bool PacketEventReader::read(EventBatch& out) {
  out.clear();
  if (pending_error_) std::rethrow_exception(std::exchange(pending_error_, nullptr));
  if (failed_) return false;
  try {
    return fill(out);
  } catch (const FormatError&) {
    // The events before the fault first, then the error; after it, nothing more.
    failed_ = true;
    if (out.empty()) throw;
    pending_error_ = std::current_exception();
    return true;
  }
}

bool PacketEventReader::fill(EventBatch& out) {
  while (out.empty()) {
    if (!next_packet()) {
      retire_decoder(out);
      return !out.empty();
    }
    if (!decoder_ || packet_.encoding != encoding_) {
      retire_decoder(out);  // a stream that changes encoding ends the old one
      decoder_ = make_packet_decoder(packet_.encoding, source_name_ + " " + packet_.location);
      if (!decoder_) {
        throw FormatError(source_name_, 0,
                          packet_.location + ": no decoder for the event encoding '" + packet_.encoding +
                              "' (evldt decodes evt2, evt3, libcaer, libcaer_cmp, mono)");
      }
      encoding_ = packet_.encoding;
    }
    decoder_->start_packet(packet_.time_base_ns);
    decoder_->decode(packet_.bytes, out);
  }
  return true;
}

std::optional<SensorSize> PacketEventReader::geometry() {
  if (const auto size = source_->geometry()) return size;
  if (!first_packet_sensor_ && !at_end_ && !packet_pending_) packet_pending_ = next_packet();
  return first_packet_sensor_;
}

void PacketEventReader::retire_decoder(EventBatch& out) {
  if (!decoder_) return;
  retired_counts_ += decoder_->counts();
  auto decoder = std::move(decoder_);
  decoder->finish(out);
}

DecodeCounts PacketEventReader::counts() const {
  DecodeCounts counts = retired_counts_;
  if (decoder_) counts += decoder_->counts();
  return counts;
}

std::unique_ptr<PacketSource> open_packet_container(const std::filesystem::path& path, const std::string& topic) {
  const auto magic = detail::container_magic(path);
  if (!magic) return nullptr;
  const std::string_view start = *magic;
  if (start.starts_with(kSqliteMagic)) return open_rosbag2(path, topic);
  if (start.starts_with(kAedat4Magic)) return open_aedat4(path);
  if (start.starts_with(kRosbag1Magic)) return open_rosbag1(path, topic);
  if (start.starts_with(kMcapMagic)) return open_mcap(path, topic);
  return nullptr;
}

}  // namespace evldt
