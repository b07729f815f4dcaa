#include "evldt/containers/aedat_images.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "container_file.hpp"
#include "evldt/events/event_decoder.hpp"

namespace evldt {
namespace {

/// The '#' text header of an AEDAT 2.0 / 3.1 file, read from its start.
detail::TextHeader read_header(const std::filesystem::path& path, std::string_view magic, const char* kind) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("cannot open " + std::string(kind) + " file '" + path.string() + "'");
  detail::TextHeader header('#');
  std::vector<std::uint8_t> chunk(4096);
  while (!header.complete()) {
    file.read(reinterpret_cast<char*>(chunk.data()), static_cast<std::streamsize>(chunk.size()));
    const auto got = static_cast<std::size_t>(file.gcount());
    if (got == 0) {
      header.finish(path.string());
      break;
    }
    header.consume(std::span(chunk.data(), got), path.string());
  }
  if (header.lines().empty() || !header.lines().front().starts_with(magic)) {
    throw std::runtime_error(path.string() + ": not an " + kind + " file (no " + std::string(magic) + " line)");
  }
  return header;
}

class Aedat31Images final : public ImageSource {
 public:
  explicit Aedat31Images(const std::filesystem::path& path) : file_(path, "AEDAT 3.1"), path_(path.string()) {
    file_.skip(read_header(path, kAedat31Magic, "AEDAT 3.1").size());
  }

  bool next(RecordingImage& image, std::string& location) override {
    const std::uint8_t* event = nullptr;
    for (;;) {
      while (next_event_ >= events_) {
        if (!read_frame_packet()) return false;
      }
      event = packet_.data() + next_event_ * event_size_;
      location = path_ + ": frame " + std::to_string(next_event_++) + " of the frame packet at byte " +
                 std::to_string(packet_at_);
      if ((detail::load_le32(event) & 1u) != 0) break;  // valid; an invalid one holds no frame
    }
    const std::uint32_t info = detail::load_le32(event);
    const std::uint32_t channels = (info >> 1) & 7u;
    const auto length_x = static_cast<std::int32_t>(detail::load_le32(event + 20));
    const auto length_y = static_cast<std::int32_t>(detail::load_le32(event + 24));
    if (channels != 1)
      throw std::runtime_error(location + ": " + std::to_string(channels) +
                               " colour channels (evldt reads grey frames)");
    if (length_x <= 0 || length_y <= 0 ||
        std::uint64_t{2} * static_cast<std::uint64_t>(length_x) * static_cast<std::uint64_t>(length_y) >
            event_size_ - kFrameHeaderBytes) {
      throw std::runtime_error(location + ": a " + std::to_string(length_x) + "x" + std::to_string(length_y) +
                               " frame does not fit its " + std::to_string(event_size_) + "-byte event");
    }
    // 31-bit times within the packet's overflow period, as the polarity events'.
    const std::uint32_t start = detail::load_le32(event + 12) & 0x7FFFFFFFu,
                        end = detail::load_le32(event + 16) & 0x7FFFFFFFu;
    image.t_us = (Timestamp{overflow_} << 31) + start + (static_cast<Timestamp>(end) - start) / 2;
    image.width = static_cast<std::uint32_t>(length_x);
    image.height = static_cast<std::uint32_t>(length_y);
    image.encoding = "mono16";
    image.big_endian = false;
    image.step = 2 * image.width;
    image.data = std::span(event + kFrameHeaderBytes, std::size_t{image.step} * image.height);
    return true;
  }

  [[nodiscard]] std::string description() const override { return "AEDAT 3.1, frame packets"; }

 private:
  static constexpr std::size_t kPacketHeaderBytes = 28, kFrameHeaderBytes = 36;
  static constexpr std::int16_t kFrameType = 2;

  /// Reads packets up to the next frame packet; false at the end of the file.
  bool read_frame_packet() {
    for (;;) {
      std::uint8_t header[kPacketHeaderBytes];
      const std::uint64_t at = file_.position();
      if (!file_.read_exactly_or_end(header, kPacketHeaderBytes, "a packet header")) return false;
      const auto type = static_cast<std::int16_t>(detail::load_le16(header));
      const auto event_size = static_cast<std::int32_t>(detail::load_le32(header + 4));
      const auto capacity = static_cast<std::int32_t>(detail::load_le32(header + 16));
      if (event_size < 0 || capacity < 0) throw FormatError(path_, at, "packet with a negative size");
      const std::uint64_t bytes =
          std::uint64_t(static_cast<std::uint32_t>(event_size)) * static_cast<std::uint32_t>(capacity);
      if (bytes > file_.size() - file_.position()) {
        throw FormatError(
            path_, at,
            "packet of " + std::to_string(bytes) + " bytes does not fit in the file (a recording cut short)");
      }
      if (type != kFrameType) {  // events, IMU samples, a compressed packet (type bit 15): not frames
        file_.skip(bytes);
        continue;
      }
      if (static_cast<std::size_t>(event_size) < kFrameHeaderBytes) {
        throw FormatError(
            path_, at,
            "frame packet with " + std::to_string(event_size) + "-byte events (a frame's header alone is 36)");
      }
      packet_.resize(bytes);
      file_.read_exactly(packet_.data(), packet_.size(), "a frame packet");
      packet_at_ = at;
      overflow_ = static_cast<std::int32_t>(detail::load_le32(header + 12));
      event_size_ = static_cast<std::size_t>(event_size);
      events_ = static_cast<std::size_t>(capacity);
      next_event_ = 0;
      return true;
    }
  }

  detail::ContainerFile file_;
  std::string path_;
  std::vector<std::uint8_t> packet_;
  std::uint64_t packet_at_ = 0;
  std::int32_t overflow_ = 0;
  std::size_t event_size_ = 0, events_ = 0, next_event_ = 0;
};

class Aedat2Images final : public ImageSource {
 public:
  explicit Aedat2Images(const std::filesystem::path& path) : file_(path, "AEDAT 2.0"), path_(path.string()) {
    const detail::TextHeader header = read_header(path, kAedat2Magic, "AEDAT 2.0");
    const auto chip = std::find_if(header.lines().begin(), header.lines().end(),
                                   [](const std::string& line) { return line.find("AEChip:") != std::string::npos; });
    if (chip == header.lines().end() || chip->find("DVS128") != std::string::npos) {
      throw std::runtime_error(path_ + ": a DVS128 recording (its chip has no APS frames)");
    }
    // The chip's size as the event decoder reads it from the header, and the first records after it
    // (a header without jAER's end line ends only where the data begins).
    auto decoder = detail::make_aedat2_decoder(path_);
    std::ifstream bytes(path, std::ios::binary);
    std::vector<std::uint8_t> start(header.size() + 4096);
    bytes.read(reinterpret_cast<char*>(start.data()), static_cast<std::streamsize>(start.size()));
    start.resize(static_cast<std::size_t>(bytes.gcount()));
    EventBatch none;
    decoder->decode(start, none);
    if (!decoder->geometry()) throw std::runtime_error(path_ + ": the header names no chip of known size");
    width_ = static_cast<std::uint32_t>(decoder->geometry()->width);
    height_ = static_cast<std::uint32_t>(decoder->geometry()->height);
    const std::size_t pixels = std::size_t{width_} * height_;
    reset_.assign(pixels, 0);
    signal_.assign(pixels, 0);
    reset_frame_.assign(pixels, 0);
    signal_frame_.assign(pixels, 0);
    frame_.assign(2 * pixels, 0);
    file_.skip(header.size());
  }

  ~Aedat2Images() override {
    if (skipped_frames_ > 0)
      spdlog::warn("{}: {} APS frame(s) incomplete (cut by the recording's start or a frame begun first), skipped",
                   path_, skipped_frames_);
  }

  bool next(RecordingImage& image, std::string& location) override {
    std::uint8_t record[8];
    while (file_.read_exactly_or_end(record, sizeof record, "an 8-byte AEDAT 2.0 event")) {
      const std::uint32_t address = detail::load_be32(record), time = detail::load_be32(record + 4);
      if (last_time_ >= time + (std::uint64_t{1} << 31)) wraps_ += 1;
      last_time_ = time;
      if ((address & 0x80000000u) == 0) continue;  // a polarity event
      const std::uint32_t read = (address >> 10) & 3u;
      const std::uint32_t x = (address >> 12) & 0x3FFu, y = (address >> 22) & 0x1FFu;
      if (read > 1 || x >= width_ || y >= height_) continue;  // colour pixels' resets, IMU samples
      const Timestamp t = (wraps_ << 32) + time;
      const std::size_t pixel = std::size_t{y} * width_ + x;
      const auto value = static_cast<std::int16_t>(address & 0x3FFu);
      if (read == 0) {
        if (reset_frame_[pixel] == frame_number_) start_frame();  // this pixel's second reset: a new frame
        reset_frame_[pixel] = frame_number_;
        reset_[pixel] = value;
        last_reset_us_ = resets_ == 0 ? t : std::max(last_reset_us_, t);
        ++resets_;
      } else if (reset_frame_[pixel] == frame_number_ && signal_frame_[pixel] != frame_number_) {
        signal_frame_[pixel] = frame_number_;
        signal_[pixel] = value;
        first_signal_us_ = signals_ == 0 ? t : std::min(first_signal_us_, t);
        if (++signals_ == reset_.size()) {
          emit(image, location);
          start_frame();
          return true;
        }
      }
    }
    return false;
  }

  [[nodiscard]] std::string description() const override { return "AEDAT 2.0, DAVIS APS samples"; }

 private:
  void start_frame() {
    if (resets_ > 0 && signals_ < reset_.size()) ++skipped_frames_;
    ++frame_number_;
    resets_ = signals_ = 0;
  }

  /// reset - signal of each pixel (the light it took in), 10 bits scaled to 16, mirrored to the
  /// events' orientation.
  void emit(RecordingImage& image, std::string& location) {
    for (std::uint32_t y = 0; y < height_; ++y) {
      for (std::uint32_t x = 0; x < width_; ++x) {
        const std::size_t pixel = std::size_t{y} * width_ + x;
        const int light = std::clamp(reset_[pixel] - signal_[pixel], 0, 1023);
        const auto value = static_cast<std::uint16_t>(light << 6);
        std::uint8_t* const out = frame_.data() + 2 * ((std::size_t{height_ - 1 - y}) * width_ + (width_ - 1 - x));
        out[0] = static_cast<std::uint8_t>(value & 0xFF);
        out[1] = static_cast<std::uint8_t>(value >> 8);
      }
    }
    image.t_us = last_reset_us_ + (first_signal_us_ - last_reset_us_) / 2;
    image.width = width_;
    image.height = height_;
    image.encoding = "mono16";
    image.big_endian = false;
    image.step = 2 * width_;
    image.data = frame_;
    location = path_ + ": APS frame " + std::to_string(emitted_++) + " (ending at byte " +
               std::to_string(file_.position()) + ")";
  }

  detail::ContainerFile file_;
  std::string path_;
  std::uint32_t width_ = 0, height_ = 0;
  std::vector<std::int16_t> reset_, signal_;
  std::vector<std::uint32_t> reset_frame_, signal_frame_;  // the frame number each pixel's read belongs to
  std::vector<std::uint8_t> frame_;
  std::uint32_t frame_number_ = 1;  // 0: no read yet
  std::size_t resets_ = 0, signals_ = 0;
  Timestamp last_reset_us_ = 0, first_signal_us_ = 0;
  std::uint32_t last_time_ = 0;
  Timestamp wraps_ = 0;
  std::uint64_t emitted_ = 0, skipped_frames_ = 0;
};

}  // namespace

std::unique_ptr<ImageSource> open_aedat31_images(const std::filesystem::path& path) {
  return std::make_unique<Aedat31Images>(path);
}

std::unique_ptr<ImageSource> open_aedat2_images(const std::filesystem::path& path) {
  return std::make_unique<Aedat2Images>(path);
}

}  // namespace evldt
