#include "evldt/containers/aedat4.hpp"

#include <flatbuffers/flatbuffers.h>

#include <limits>
#include <map>
#include <stdexcept>

#include "aedat4_header_generated.h"
#include "container_file.hpp"
#include "decompress.hpp"
#include "dv_frame_generated.h"
#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_format.hpp"
#include "evldt/events/size_prefixed_flatbuffer.hpp"

namespace evldt {
namespace {

/// The streams the XML info node describes: for each "<node ... path=".../outInfo/ID/">" its
/// attributes, and those of its "info/" child node (sizeX, sizeY, source).
struct StreamInfo {
  std::string type;
  std::optional<SensorSize> sensor;
  std::string source;
};

std::string_view attribute_of(std::string_view tag, std::string_view name) {
  const std::string key = std::string(name) + "=\"";
  const auto at = tag.find(key);
  if (at == std::string_view::npos) return {};
  const auto start = at + key.size();
  const auto end = tag.find('"', start);
  return end == std::string_view::npos ? std::string_view{} : tag.substr(start, end - start);
}

std::map<int, StreamInfo> parse_streams(std::string_view xml) {
  std::map<std::string, std::map<std::string, std::string>> attributes_by_path;
  std::string path;
  for (std::size_t at = xml.find('<'); at != std::string_view::npos; at = xml.find('<', at + 1)) {
    const auto close = xml.find('>', at);
    if (close == std::string_view::npos) break;
    const std::string_view tag = xml.substr(at, close - at + 1);
    if (tag.starts_with("<node")) {
      path = std::string(attribute_of(tag, "path"));
    } else if (tag.starts_with("<attr")) {
      const auto value_end = xml.find("</attr>", close);
      if (value_end == std::string_view::npos) break;
      attributes_by_path[path][std::string(attribute_of(tag, "key"))] =
          std::string(xml.substr(close + 1, value_end - close - 1));
    }
  }
  std::map<int, StreamInfo> streams;
  const std::string_view marker = "/outInfo/";
  for (const auto& entry : attributes_by_path) {
    const std::string& node_path = entry.first;
    const auto& attributes = entry.second;  // a plain reference: lambdas cannot capture bindings (clang 14)
    const auto at = node_path.find(marker);
    if (at == std::string::npos) continue;
    const std::string rest = node_path.substr(at + marker.size());  // "ID/" or "ID/info/"
    const auto slash = rest.find('/');
    if (slash == std::string::npos || slash == 0 || rest.find_first_not_of("0123456789") != slash) continue;
    const int id = std::stoi(rest.substr(0, slash));
    StreamInfo& stream = streams[id];
    const auto get = [&](const char* key) {
      const auto found = attributes.find(key);
      return found == attributes.end() ? std::string() : found->second;
    };
    if (rest.size() == slash + 1) {
      stream.type = get("typeIdentifier");
    } else if (rest.substr(slash + 1) == "info/") {
      stream.source = get("source");
      try {
        const SensorSize size{std::stoi(get("sizeX")), std::stoi(get("sizeY"))};
        if (size.valid()) stream.sensor = size;
      } catch (const std::exception&) {  // no or malformed size: the stream says none
      }
    }
  }
  return streams;
}

/// The container: its header, the streams it describes, and the packets of one stream.
class Aedat4Container {
 public:
  /// A file (its version line first) or a DV network stream (the same without it, and without a
  /// data table: it ends when the server closes it).
  Aedat4Container(std::unique_ptr<detail::ContainerInput> input, bool network)
      : input_(std::move(input)), file_(*input_), path_(file_.path()), network_(network) {
    if (!network_) {
      std::string magic(kAedat4Magic.size(), '\0');
      file_.read_exactly(magic.data(), magic.size(), "the version line");
      if (magic != kAedat4Magic) throw FormatError(path_, 0, "not an AEDAT 4.0 file");
    }
    std::vector<std::uint8_t> header(4);
    header_at_ = file_.position();
    file_.read_exactly(header.data(), 4, "the header size");
    const std::uint32_t header_size = detail::load_le32(header.data());
    if (header_size > detail::kMaxDecompressedBytes)
      throw FormatError(path_, file_.position() - 4, "header size " + std::to_string(header_size));
    header.resize(4 + header_size);
    file_.read_exactly(header.data() + 4, header_size, "the header");
    // The identifier "IOHE" is DV's; other writers leave it out, so it is not required. The verifier
    // checks the rest (every offset, the table's fields in whatever order its vtable lists them).
    std::vector<std::uint64_t> aligned;
    const aedat4::IOHeader* io = verified_size_prefixed_root<aedat4::IOHeader>(header, aligned);
    if (io == nullptr) throw FormatError(path_, header_at_, "the header is not a valid IOHeader FlatBuffer");
    compression_ = io->compression();
    if (compression_ < aedat4::CompressionType::NONE || compression_ > aedat4::CompressionType::ZSTD_HIGH) {
      throw FormatError(path_, header_at_, "unknown compression " + std::to_string(static_cast<int>(compression_)));
    }
    data_end_ = network_                       ? std::numeric_limits<std::uint64_t>::max()
                : io->dataTablePosition() >= 0 ? static_cast<std::uint64_t>(io->dataTablePosition())
                                               : file_.size();
    streams_ = parse_streams(io->infoNode() ? io->infoNode()->string_view() : std::string_view());
  }

  /// The first stream of `type` ("EVTS": polarity events, "FRME": frames), or none.
  [[nodiscard]] std::optional<std::pair<int, StreamInfo>> stream_of_type(std::string_view type) const {
    for (const auto& [id, stream] : streams_) {
      if (stream.type == type) return std::pair(id, stream);
    }
    return std::nullopt;
  }

  /// The next packet of stream `id`, decompressed into `payload`; false at the end. `at`: where the
  /// packet starts, for errors. Packets of other streams are passed over and counted.
  bool next_packet(int id, std::vector<std::uint8_t>& payload, std::uint64_t& at) {
    while (file_.position() + 8 <= data_end_) {
      std::uint8_t header[8];
      at = file_.position();
      if (network_) {
        if (!file_.read_exactly_or_end(header, 8, "a packet header")) return false;  // the server closed the stream
      } else {
        file_.read_exactly(header, 8, "a packet header");
      }
      const auto stream = static_cast<std::int32_t>(detail::load_le32(header));
      const std::uint32_t size = detail::load_le32(header + 4);
      if (size > detail::kMaxDecompressedBytes || size > data_end_ - file_.position()) {
        throw FormatError(path_, at, "packet of " + std::to_string(size) + " bytes does not fit in the file");
      }
      if (stream != id) {
        file_.skip(size);
        ++skipped_;
        continue;
      }
      compressed_.resize(size);
      file_.read_exactly(compressed_.data(), size, "a packet");
      try {
        decompress(payload);
      } catch (const std::runtime_error& error) {
        throw FormatError(path_, at + 8, error.what());
      }
      return true;
    }
    if (file_.position() < data_end_ && data_end_ == file_.size()) {
      throw FormatError(path_, file_.position(), "file ends inside a packet header (a recording cut short)");
    }
    return false;
  }

  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::uint64_t header_at() const { return header_at_; }
  [[nodiscard]] std::string compression_name() const { return aedat4::EnumNameCompressionType(compression_); }
  [[nodiscard]] double progress() const {
    if (network_) return 0.0;
    return data_end_ == 0 ? 1.0 : static_cast<double>(file_.position()) / static_cast<double>(data_end_);
  }
  [[nodiscard]] std::uint64_t skipped_packets() const { return skipped_; }

 private:
  void decompress(std::vector<std::uint8_t>& out) {
    switch (compression_) {
      case aedat4::CompressionType::NONE:
        out = compressed_;
        return;
      case aedat4::CompressionType::LZ4:
      case aedat4::CompressionType::LZ4_HIGH:
        detail::decompress_lz4_frame(compressed_, out);
        return;
      case aedat4::CompressionType::ZSTD:
      case aedat4::CompressionType::ZSTD_HIGH:
        detail::decompress_zstd_frame(compressed_, out);
        return;
    }
  }

  std::unique_ptr<detail::ContainerInput> input_;
  detail::ContainerInput& file_;
  std::string path_;
  bool network_;
  std::uint64_t header_at_ = 0;
  std::uint64_t data_end_ = 0;
  aedat4::CompressionType compression_ = aedat4::CompressionType::NONE;
  std::map<int, StreamInfo> streams_;
  std::uint64_t skipped_ = 0;
  std::vector<std::uint8_t> compressed_;
};

class Aedat4Source final : public PacketSource {
 public:
  Aedat4Source(std::unique_ptr<detail::ContainerInput> input, bool network) : container_(std::move(input), network) {
    const auto events = container_.stream_of_type("EVTS");
    if (!events)
      throw FormatError(container_.path(), container_.header_at(), "no polarity event stream (EVTS) in the header");
    stream_id_ = events->first;
    sensor_ = events->second.sensor;
    camera_ = events->second.source;
  }

  bool next(RecordingPacket& packet) override {
    std::uint64_t at = 0;
    if (!container_.next_packet(stream_id_, packet.bytes, at)) return false;
    packet.location = "byte " + std::to_string(at);
    packet.encoding = "dv_events";
    packet.time_base_ns = 0;
    packet.sensor = sensor_;
    return true;
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return sensor_; }
  [[nodiscard]] std::string camera() const override { return camera_; }
  [[nodiscard]] std::string description() const override {
    return "AEDAT 4.0, stream " + std::to_string(stream_id_) + " (polarity events, " + container_.compression_name() +
           ")";
  }
  [[nodiscard]] double progress() const override { return container_.progress(); }
  [[nodiscard]] std::uint64_t skipped_packets() const override { return container_.skipped_packets(); }

 private:
  Aedat4Container container_;
  int stream_id_ = -1;
  std::optional<SensorSize> sensor_;
  std::string camera_;
};

class Aedat4Images final : public ImageSource {
 public:
  explicit Aedat4Images(const std::filesystem::path& path)
      : container_(std::make_unique<detail::ContainerFile>(path, "AEDAT 4"), false) {
    const auto frames = container_.stream_of_type("FRME");
    if (!frames) throw std::runtime_error(container_.path() + ": no frame stream (FRME) in the header");
    stream_id_ = frames->first;
  }

  bool next(RecordingImage& image, std::string& location) override {
    std::uint64_t at = 0;
    if (!container_.next_packet(stream_id_, payload_, at)) return false;
    location = container_.path() + ": frame packet at byte " + std::to_string(at);
    // The identifier FRME is DV's alone: not required.
    const dv::Frame* frame = verified_size_prefixed_root<dv::Frame>(payload_, aligned_);
    if (frame == nullptr) throw std::runtime_error(location + ": not a valid Frame FlatBuffer");
    int channels = 1;
    switch (frame->format()) {
      case dv::FrameFormat::OPENCV_8U_C1:
        image.encoding = "mono8";
        break;
      case dv::FrameFormat::OPENCV_8U_C3:
        image.encoding = "bgr8";
        channels = 3;
        break;
      default:
        throw std::runtime_error(location + ": pixel format " + std::to_string(static_cast<int>(frame->format())) +
                                 " is not one evldt reads (grey or BGR, 8 bits)");
    }
    const std::uint64_t width = frame->sizeX() > 0 ? static_cast<std::uint64_t>(frame->sizeX()) : 0;
    const std::uint64_t height = frame->sizeY() > 0 ? static_cast<std::uint64_t>(frame->sizeY()) : 0;
    const std::uint64_t pixel_bytes = frame->pixels() ? frame->pixels()->size() : 0;
    if (width == 0 || height == 0 || pixel_bytes < width * height * static_cast<std::uint64_t>(channels)) {
      throw std::runtime_error(location + ": " + std::to_string(pixel_bytes) + " bytes of pixels for a " +
                               std::to_string(width) + "x" + std::to_string(height) + " frame");
    }
    // The middle of the exposure where the frame gives it; else its time stamp (its exposure's start).
    const std::int64_t start = frame->timestampStartOfExposure(), end = frame->timestampEndOfExposure();
    image.t_us = start > 0 && end >= start ? start + (end - start) / 2 : frame->timestamp();
    image.width = static_cast<std::uint32_t>(width);
    image.height = static_cast<std::uint32_t>(height);
    image.big_endian = false;
    image.step = static_cast<std::uint32_t>(width) * static_cast<std::uint32_t>(channels);
    image.data = std::span(frame->pixels()->data(), frame->pixels()->size());
    return true;
  }

  [[nodiscard]] std::string description() const override {
    return "AEDAT 4.0, stream " + std::to_string(stream_id_) + " (frames, " + container_.compression_name() + ")";
  }

 private:
  Aedat4Container container_;
  int stream_id_ = -1;
  std::vector<std::uint8_t> payload_;
  std::vector<std::uint64_t> aligned_;  ///< where a frame not aligned from its own origin is read
};

}  // namespace

std::unique_ptr<PacketSource> open_aedat4(const std::filesystem::path& path) {
  return std::make_unique<Aedat4Source>(std::make_unique<detail::ContainerFile>(path, "AEDAT 4"), false);
}

std::unique_ptr<PacketSource> open_aedat4_stream(std::unique_ptr<ByteSource> bytes) {
  return std::make_unique<Aedat4Source>(std::make_unique<detail::ContainerStream>(std::move(bytes)), true);
}

std::unique_ptr<ImageSource> open_aedat4_images(const std::filesystem::path& path) {
  return std::make_unique<Aedat4Images>(path);
}

}  // namespace evldt
