#pragma once
// Incremental decoders: recording bytes in, events out. Input may arrive in chunks of any size; a chunk
// boundary may split a header line, a text line or a binary word, so every decoder carries the partial
// piece over to the next chunk.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {

/// What a decoder passed over without failing: words of a type the specification reserves or does
/// not describe, skipped as the vendor SDK skips them (some cameras pad their stream with such
/// words), and external-trigger events, counted but not stored (lines have no use for them).
struct DecodeCounts {
  std::uint64_t skipped_words = 0;
  std::uint64_t trigger_events = 0;

  DecodeCounts& operator+=(const DecodeCounts& other) {
    skipped_words += other.skipped_words;
    trigger_events += other.trigger_events;
    return *this;
  }
  friend bool operator==(const DecodeCounts&, const DecodeCounts&) = default;
};

class EventDecoder {
 public:
  virtual ~EventDecoder() = default;

  /// Decodes the chunk, appending every complete valid event to `out`. On corrupt data it appends all
  /// valid events before the bad bytes and then throws FormatError(source, absolute byte offset, reason).
  virtual void decode(std::span<const std::uint8_t> chunk, EventBatch& out) = 0;

  /// End of input. Appends the event of a last ECD text line that has no '\n'; throws FormatError at the
  /// offset of any partial record, word or line (or unterminated header) that remains.
  virtual void finish(EventBatch& out) = 0;

  /// Sensor size from the file header once it is parsed (EVT 2.0/3.0, dat); nullopt if the header has
  /// none or the format has no header (ECD text).
  [[nodiscard]] virtual std::optional<SensorSize> geometry() const = 0;

  /// Skipped words and trigger events so far (formats without either: zero).
  [[nodiscard]] virtual DecodeCounts counts() const { return {}; }

  /// A container's packet begins (the bytes of the next decode() calls): its time base in ns, which
  /// encodings that count time from the packet use (libcaer, libcaer_cmp); the others ignore it.
  virtual void start_packet(std::int64_t /*time_base_ns*/) {}
};

/// Whether the bytes begin with Prophesee's '%' text header (a RAW file) or are bare words (a
/// packet of a container such as a ROS bag).
enum class RawFraming { WithHeader, BareWords };

/// `source_name` (usually the file path) prefixes every FormatError message.
/// EVT 3.0 events before the first EVT_TIME_HIGH word have no known time and are dropped, not reported.
/// Time wraps (24-bit EVT 3.0, 34-bit EVT 2.0, 32-bit dat) are unwrapped: a time base that goes back by
/// half its range or more counts as one wrap, so output times keep increasing over long recordings.
std::unique_ptr<EventDecoder> make_decoder(EventFormat format, std::string source_name);

/// The decoder of one packet encoding of a container, by the name the container gives it
/// (event_camera_msgs' encoding field): "evt2", "evt3" (bare Prophesee words, one stream across
/// packets), "libcaer", "libcaer_cmp" (iniVation, time from each packet's time base), "dv_events"
/// (an AEDAT 4.0 polarity packet, handed whole), "dvs_events" (a dvs_msgs/EventArray's records),
/// "mono" (event_camera_codecs' plain 64-bit events); nullptr for an encoding evldt does not decode.
/// Packet offsets in errors are relative to the packet.
std::unique_ptr<EventDecoder> make_packet_decoder(std::string_view encoding, std::string source_name);

namespace detail {

// One factory per format source file; make_decoder picks among them.
std::unique_ptr<EventDecoder> make_ecd_text_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_evt2_decoder(std::string source_name, RawFraming framing);
std::unique_ptr<EventDecoder> make_evt3_decoder(std::string source_name, RawFraming framing);
std::unique_ptr<EventDecoder> make_dat_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_evt21_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_aedat2_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_aedat31_decoder(std::string source_name);
/// libcaer's AEDAT 3.1 network stream (TCP): its 20-byte network header (magic, sequence, version),
/// then the packets of an AEDAT 3.1 file. It names no sensor size.
std::unique_ptr<EventDecoder> make_aedat31_network_decoder(std::string source_name);
/// Whether bytes start as libcaer's network header does (its magic number, little-endian).
bool starts_as_aedat31_network(std::span<const std::uint8_t> bytes);
std::unique_ptr<EventDecoder> make_event_stream_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_libcaer_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_libcaer_compressed_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_dv_events_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_dvs_events_decoder(std::string source_name);
std::unique_ptr<EventDecoder> make_mono_decoder(std::string source_name);

/// A time in ns as evldt's us, rounded down (container time bases may be before 1970: negative).
inline Timestamp floor_ns_to_us(std::int64_t ns) { return ns / 1000 - (ns % 1000 < 0 ? 1 : 0); }

/// The text header that recordings start with: lines beginning with a marker, '%' (Prophesee RAW and
/// dat) or '#' (AEDAT 2.0 / 3.1). It ends at the first line that does not start with the marker (the
/// binary data), or after the line its writers put last so that data starting with the marker byte
/// is not taken for header: "% end", "#!END-HEADER" (cAER), "#End Of ASCII Header" (jAER).
class TextHeader {
 public:
  explicit TextHeader(char marker = '%') : marker_(marker) {}
  /// Consumes header bytes from the front of `bytes` and returns how many; the rest is data.
  /// Throws FormatError for a header line too long to be one (binary data starting with '%').
  std::size_t consume(std::span<const std::uint8_t> bytes, const std::string& source);
  /// The same for a decoder: consumes header bytes from the front of `chunk`, leaving it the data;
  /// true once the header is complete.
  bool take(std::span<const std::uint8_t>& chunk, const std::string& source) {
    chunk = chunk.subspan(consume(chunk, source));
    return complete_;
  }
  /// End of input: a header line without its '\n' means a truncated file.
  void finish(const std::string& source) const;

  [[nodiscard]] bool complete() const { return complete_; }
  /// Bytes of header consumed so far; once complete(), the offset of the first data byte.
  [[nodiscard]] std::uint64_t size() const { return size_; }
  /// Complete header lines without the line end.
  [[nodiscard]] const std::vector<std::string>& lines() const { return lines_; }

  /// From "% geometry WxH", "% format NAME;height=H;width=W" or "% Width W" + "% Height H"; in a header
  /// that names none (the 2020-era SDK), the sensor the vendor tools know from "% system_ID" or
  /// "% plugin_name" (Gen3/3.1 640x480, Gen4/4.1/IMX636 1280x720).
  [[nodiscard]] std::optional<SensorSize> geometry() const;
  /// The data encoding the header names: "% format EVT3;..." -> "EVT3", "% evt 2.0" -> "EVT2",
  /// "% evt 2.1" -> "EVT21"; else the default of a known "% system_ID"; nullopt if none.
  [[nodiscard]] std::optional<std::string> encoding() const;
  /// The value of "% KEY value", or of the option "KEY=value" of the "% format" line; nullopt if absent.
  [[nodiscard]] std::optional<std::string> option(std::string_view key) const;
  /// The "% system_ID" (decimal), if the header has one.
  [[nodiscard]] std::optional<int> system_id() const;

 private:
  [[nodiscard]] bool is_end_line(std::string_view line) const;

  char marker_;
  std::vector<std::string> lines_;
  std::string line_;  // the header line being read
  std::uint64_t line_start_ = 0;
  bool in_line_ = false;
  bool complete_ = false;
  std::uint64_t size_ = 0;
};

/// EVT2 / EVT3 / EVT21 for the encodings "EVT2" / "EVT3" / "EVT21"; nullopt for any other.
std::optional<EventFormat> raw_format_from_encoding(std::string_view encoding);

inline std::uint16_t load_le16(const std::uint8_t* bytes) {
  return static_cast<std::uint16_t>(bytes[0] | (bytes[1] << 8));
}
inline std::uint32_t load_le32(const std::uint8_t* bytes) {
  return static_cast<std::uint32_t>(bytes[0]) | (static_cast<std::uint32_t>(bytes[1]) << 8) |
         (static_cast<std::uint32_t>(bytes[2]) << 16) | (static_cast<std::uint32_t>(bytes[3]) << 24);
}

/// Big-endian, as jAER's AEDAT 2.0 writes its addresses and times.
inline std::uint32_t load_be32(const std::uint8_t* bytes) {
  return static_cast<std::uint32_t>(bytes[0]) << 24 | static_cast<std::uint32_t>(bytes[1]) << 16 |
         static_cast<std::uint32_t>(bytes[2]) << 8 | bytes[3];
}

inline std::uint64_t load_le64(const std::uint8_t* bytes) {
  return static_cast<std::uint64_t>(load_le32(bytes)) | (static_cast<std::uint64_t>(load_le32(bytes + 4)) << 32);
}

/// Cuts a byte stream arriving in chunks into fixed-size words, carrying a word split by a chunk
/// boundary over to the next chunk. A template so that the per-word call inlines.
template <std::size_t WordBytes>
class WordSplitter {
 public:
  /// Where the first word starts in the file (after the header).
  void set_offset(std::uint64_t offset) { offset_ = offset; }

  /// Calls on_word(const std::uint8_t* word, std::uint64_t word_offset) for every complete word.
  template <class OnWord>
  void feed(std::span<const std::uint8_t> bytes, OnWord&& on_word) {
    if (carried_ > 0) {
      const std::size_t take = std::min(WordBytes - carried_, bytes.size());
      std::copy_n(bytes.data(), take, carry_.data() + carried_);
      carried_ += take;
      bytes = bytes.subspan(take);
      if (carried_ < WordBytes) return;
      carried_ = 0;
      on_word(carry_.data(), offset_);
      offset_ += WordBytes;
    }
    const std::size_t whole = bytes.size() - bytes.size() % WordBytes;
    for (std::size_t i = 0; i < whole; i += WordBytes) on_word(bytes.data() + i, offset_ + i);
    offset_ += whole;
    carried_ = bytes.size() - whole;
    std::copy_n(bytes.data() + whole, carried_, carry_.data());
  }

  /// Bytes of an incomplete word waiting for the next chunk, and where that word starts.
  [[nodiscard]] std::size_t carried() const { return carried_; }
  [[nodiscard]] std::uint64_t offset() const { return offset_; }

 private:
  std::array<std::uint8_t, WordBytes> carry_{};
  std::size_t carried_ = 0;
  std::uint64_t offset_ = 0;  // of the next word to complete
};

}  // namespace detail
}  // namespace evldt
