// iniVation's and jAER's older recording formats. Both start with a text header of '#' lines.
//
// AEDAT 3.1 (cAER, DV before 2019: DAVIS, DVS128): "#!AER-DAT3.1", "#Source N: NAME", ...,
// "#!END-HEADER", then little-endian packets: a 28-byte header (int16 type, int16 source, int32
// event size, int32 timestamp offset, int32 timestamp overflow, int32 capacity, int32 number, int32
// valid) and capacity x size bytes of events. Polarity events (type 1, 8 bytes): uint32 data
// ([0] valid, [1] polarity 1 ON, [16:2] y, [31:17] x; origin top left), int32 time; the time is
// overflow << 31 | time. Invalid events are skipped and counted; other packet types are skipped
// whole (compressed packets, type bit 15, too). The sensor size comes from the source's name.
//
// AEDAT 2.0 (jAER): "#!AER-DAT2.0", "# AEChip: <class>", ..., then big-endian 8-byte records:
// int32 address, int32 time (us; unwrapped across 2^32). The address depends on the chip:
//   DVS128: [0] polarity (0 ON), [7:1] x, [14:8] y (both mirrored), [15] external, [31] special;
//   DAVIS:  [31] APS/IMU (skipped), [10] external (counted as a trigger), [11] polarity (1 ON),
//           [21:12] x, [30:22] y (both mirrored: jAER's origin is the bottom left).
// The chip comes from "# AEChip:" (a file without one is a DVS128: only they were recorded then).

#include <array>
#include <cstring>

#include "evldt/events/event_decoder.hpp"

namespace evldt::detail {
namespace {

struct KnownChip {
  const char* name_part;  ///< matched within the source / chip name
  SensorSize sensor;
  bool dvs128_layout;
};
// Most specific first: "DAVIS128" before "128", "DAVIS346" before "DAVIS".
constexpr KnownChip kKnownChips[] = {
    {"DAVIS128", {128, 128}, false}, {"DVS128", {128, 128}, true}, {"346", {346, 260}, false},
    {"240", {240, 180}, false},      {"640", {640, 480}, false},   {"208", {208, 192}, false},
};

std::string uppercase(std::string text) {
  for (char& c : text) c = (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
  return text;
}

const KnownChip* known_chip(const std::string& name) {
  const std::string upper = uppercase(name);
  for (const KnownChip& chip : kKnownChips) {
    if (upper.find(chip.name_part) != std::string::npos) return &chip;
  }
  return nullptr;
}

/// "dvsSizeX=346,dvsSizeY=260" in a re-logged source's name.
std::optional<SensorSize> explicit_size(const std::string& name) {
  const auto value_of = [&](const char* key) -> std::optional<int> {
    const auto at = name.find(key);
    if (at == std::string::npos) return std::nullopt;
    int value = 0;
    const char* digits = name.c_str() + at + std::strlen(key);
    for (; *digits >= '0' && *digits <= '9' && value < 100000; ++digits) value = value * 10 + (*digits - '0');
    return value;
  };
  const auto width = value_of("dvsSizeX="), height = value_of("dvsSizeY=");
  if (!width || !height) return std::nullopt;
  const SensorSize size{*width, *height};
  return size.valid() ? std::optional(size) : std::nullopt;
}

/// The value after "KEY" in the first header line that has it ("#Source 1: DAVIS346B" -> "1: DAVIS346B").
std::optional<std::string> header_value(const TextHeader& header, std::string_view key) {
  for (const std::string& line : header.lines()) {
    std::string_view rest(line);
    rest.remove_prefix(1);  // the '#'
    while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
    if (rest.starts_with(key)) return std::string(rest.substr(key.size()));
  }
  return std::nullopt;
}

// libcaer's network header (network.h): int64 magic, int64 sequence number, int8 version, int8
// format, int16 source id, little-endian; a TCP stream sends it once, then the packets.
constexpr std::size_t kNetworkHeaderBytes = 20;
constexpr std::uint64_t kNetworkMagic = 0x1D378BC90B9A6658;
constexpr std::uint8_t kNetworkVersion = 1;

/// An AEDAT 3.1 file ('#' text header) or network stream (network header), then packets.
class Aedat31Decoder final : public EventDecoder {
 public:
  Aedat31Decoder(std::string source, bool network) : source_(std::move(source)), header_('#'), network_(network) {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    if (network_ && network_header_bytes_ < kNetworkHeaderBytes) {
      const std::size_t take = std::min(chunk.size(), kNetworkHeaderBytes - network_header_bytes_);
      std::memcpy(network_header_.data() + network_header_bytes_, chunk.data(), take);
      network_header_bytes_ += take;
      advance(chunk, take);
      if (network_header_bytes_ < kNetworkHeaderBytes) return;
      if (load_le64(network_header_.data()) != kNetworkMagic) {
        throw FormatError(source_, 0, "not an AEDAT 3.1 network stream (no libcaer network magic number)");
      }
      if (network_header_[16] != kNetworkVersion) {
        throw FormatError(source_, 16, "AEDAT 3 network version " + std::to_string(network_header_[16]) + ", not 1");
      }
    }
    if (!network_ && !header_.complete()) {
      if (!header_.take(chunk, source_)) return;
      read_header();
      offset_ = header_.size();
    }
    while (!chunk.empty()) {
      if (remaining_ == 0) {  // a packet header
        const std::size_t take = std::min(chunk.size(), kPacketHeaderBytes - header_bytes_);
        std::memcpy(packet_header_.data() + header_bytes_, chunk.data(), take);
        header_bytes_ += take;
        advance(chunk, take);
        if (header_bytes_ == kPacketHeaderBytes) begin_packet_from_header();
        continue;
      }
      if (!polarity_packet_) {
        const auto skip = static_cast<std::size_t>(std::min<std::uint64_t>(remaining_, chunk.size()));
        remaining_ -= skip;
        advance(chunk, skip);
        continue;
      }
      events_.feed(chunk.first(static_cast<std::size_t>(std::min<std::uint64_t>(remaining_, chunk.size()))),
                   [&](const std::uint8_t* event, std::uint64_t) { decode_event(event, out); });
      const auto fed = static_cast<std::size_t>(std::min<std::uint64_t>(remaining_, chunk.size()));
      remaining_ -= fed;
      advance(chunk, fed);
    }
  }

  void finish(EventBatch&) override {
    if (network_ && network_header_bytes_ < kNetworkHeaderBytes) {
      throw FormatError(source_, 0, "stream ends inside the AEDAT 3.1 network header");
    }
    if (!network_) header_.finish(source_);
    if (header_bytes_ > 0 || remaining_ > 0) {
      throw FormatError(source_, header_bytes_ > 0 ? offset_ - header_bytes_ : packet_start_,
                        network_ ? "stream ends inside a packet" : "file ends inside a packet (a recording cut short)");
    }
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return sensor_; }
  [[nodiscard]] DecodeCounts counts() const override { return counts_; }

 private:
  static constexpr std::size_t kPacketHeaderBytes = 28;
  static constexpr std::int16_t kPolarityType = 1;
  static constexpr std::int32_t kPolarityEventBytes = 8;

  void read_header() {
    const auto version = header_.lines().empty() ? std::string() : header_.lines().front();
    if (!version.starts_with("#!AER-DAT3")) throw FormatError(source_, 0, "not an AEDAT 3 file (no #!AER-DAT3.x line)");
    if (const auto source = header_value(header_, "Source ")) {
      sensor_ = explicit_size(*source);
      if (!sensor_) {
        if (const KnownChip* chip = known_chip(*source)) sensor_ = chip->sensor;
      }
    }
  }

  void advance(std::span<const std::uint8_t>& chunk, std::size_t count) {
    chunk = chunk.subspan(count);
    offset_ += count;
  }

  void begin_packet_from_header() {
    header_bytes_ = 0;
    const auto type = static_cast<std::int16_t>(load_le16(packet_header_.data()));
    const auto event_size = static_cast<std::int32_t>(load_le32(packet_header_.data() + 4));
    overflow_ = static_cast<std::int32_t>(load_le32(packet_header_.data() + 12));
    const auto capacity = static_cast<std::int32_t>(load_le32(packet_header_.data() + 16));
    packet_start_ = offset_ - kPacketHeaderBytes;
    if (event_size < 0 || capacity < 0) throw FormatError(source_, packet_start_, "packet with a negative size");
    remaining_ = static_cast<std::uint64_t>(event_size) * static_cast<std::uint64_t>(capacity);
    polarity_packet_ = type == kPolarityType && event_size == kPolarityEventBytes;  // compressed: type has bit 15
    if (!polarity_packet_) ++counts_.skipped_words;  // a packet of another type, skipped whole
  }

  void decode_event(const std::uint8_t* event, EventBatch::Appender& out) {
    const std::uint32_t data = load_le32(event);
    if ((data & 1u) == 0) {
      ++counts_.skipped_words;
      return;
    }
    const Timestamp t = (Timestamp{overflow_} << 31) | static_cast<std::uint32_t>(load_le32(event + 4) & 0x7FFFFFFFu);
    out.push_back(t, static_cast<std::uint16_t>(data >> 17), static_cast<std::uint16_t>((data >> 2) & 0x7FFF),
                  (data & 2u) != 0 ? std::int8_t{1} : std::int8_t{-1});
  }

  std::string source_;
  TextHeader header_;
  bool network_;
  std::array<std::uint8_t, kNetworkHeaderBytes> network_header_{};
  std::size_t network_header_bytes_ = 0;
  std::optional<SensorSize> sensor_;
  std::array<std::uint8_t, kPacketHeaderBytes> packet_header_{};
  std::size_t header_bytes_ = 0;
  std::uint64_t remaining_ = 0;  // bytes of the current packet's events
  bool polarity_packet_ = false;
  std::int32_t overflow_ = 0;
  std::uint64_t offset_ = 0;  // of the next byte
  std::uint64_t packet_start_ = 0;
  WordSplitter<kPolarityEventBytes> events_;
  DecodeCounts counts_;
};

class Aedat2Decoder final : public EventDecoder {
 public:
  explicit Aedat2Decoder(std::string source) : source_(std::move(source)), header_('#') {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    if (!header_.complete()) {
      if (!header_.take(chunk, source_)) return;
      read_header();
      records_.set_offset(header_.size());
    }
    records_.feed(chunk, [&](const std::uint8_t* record, std::uint64_t) {
      decode_record(load_be32(record), load_be32(record + 4), out);
    });
  }

  void finish(EventBatch&) override {
    header_.finish(source_);
    if (records_.carried() > 0)
      throw FormatError(source_, records_.offset(), "file ends inside an 8-byte AEDAT 2.0 event");
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return sensor_; }
  [[nodiscard]] DecodeCounts counts() const override { return counts_; }

 private:
  void read_header() {
    const auto version = header_.lines().empty() ? std::string() : header_.lines().front();
    if (!version.starts_with("#!AER-DAT2"))
      throw FormatError(source_, 0, "not an AEDAT 2.0 file (no #!AER-DAT2.0 line)");
    const auto chip_name = header_value(header_, "AEChip:");
    const KnownChip* chip = chip_name ? known_chip(*chip_name) : &kKnownChips[1];  // no chip line: a DVS128
    if (!chip) throw FormatError(source_, 0, "unknown chip '" + *chip_name + "': its event addresses cannot be read");
    sensor_ = chip->sensor;
    dvs128_ = chip->dvs128_layout;
  }

  void decode_record(std::uint32_t address, std::uint32_t time, EventBatch::Appender& out) {
    if (last_time_ >= time + (std::uint64_t{1} << 31)) wraps_ += 1;
    last_time_ = time;
    const Timestamp t = (wraps_ << 32) + time;
    const auto width = static_cast<std::uint32_t>(sensor_->width), height = static_cast<std::uint32_t>(sensor_->height);
    if (dvs128_) {
      if ((address & 0x80008000u) != 0) {
        ++counts_.skipped_words;  // special or external events
        return;
      }
      out.push_back(t, static_cast<std::uint16_t>(127 - ((address >> 1) & 0x7F)),
                    static_cast<std::uint16_t>(127 - ((address >> 8) & 0x7F)),
                    (address & 1u) == 0 ? std::int8_t{1} : std::int8_t{-1});
      return;
    }
    if ((address & 0x80000000u) != 0) {
      ++counts_.skipped_words;  // APS and IMU samples
      return;
    }
    if ((address & 0x400u) != 0) {
      ++counts_.trigger_events;
      return;
    }
    const std::uint32_t x = (address >> 12) & 0x3FF, y = (address >> 22) & 0x1FF;
    if (x >= width || y >= height) {
      ++counts_.skipped_words;  // not a pixel of this chip: mirroring it would wrap around
      return;
    }
    out.push_back(t, static_cast<std::uint16_t>(width - 1 - x), static_cast<std::uint16_t>(height - 1 - y),
                  (address & 0x800u) != 0 ? std::int8_t{1} : std::int8_t{-1});
  }

  std::string source_;
  TextHeader header_;
  std::optional<SensorSize> sensor_;
  bool dvs128_ = true;
  WordSplitter<8> records_;
  std::uint32_t last_time_ = 0;
  Timestamp wraps_ = 0;
  DecodeCounts counts_;
};

}  // namespace

std::unique_ptr<EventDecoder> make_aedat31_decoder(std::string source_name) {
  return std::make_unique<Aedat31Decoder>(std::move(source_name), false);
}
std::unique_ptr<EventDecoder> make_aedat31_network_decoder(std::string source_name) {
  return std::make_unique<Aedat31Decoder>(std::move(source_name), true);
}
bool starts_as_aedat31_network(std::span<const std::uint8_t> bytes) {
  return bytes.size() >= 8 && load_le64(bytes.data()) == kNetworkMagic;
}
std::unique_ptr<EventDecoder> make_aedat2_decoder(std::string source_name) {
  return std::make_unique<Aedat2Decoder>(std::move(source_name));
}

}  // namespace evldt::detail
