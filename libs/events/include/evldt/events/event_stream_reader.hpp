#pragma once
// Reading a recording from any source of bytes (a file, one that grows, standard input, a TCP stream)
// chunk by chunk, never the whole at once: its header parsed, then the decoder of its format.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "evldt/events/byte_source.hpp"
#include "evldt/events/event.hpp"
#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {

/// Bytes read and decoded at a time: small enough that decoding them (about 0.1 ms) never holds a
/// paced replay's batches back, which a megabyte (some 5 ms, longer on first touch) did: they then
/// went out in bursts.
inline constexpr std::size_t kReadChunkBytes = std::size_t{1} << 16;

class EventStreamReader {
 public:
  /// Reads `bytes` and parses the header. The format is `format` if given, else told by the first
  /// bytes (AEDAT 2.0 and 3.1, Event Stream), else by `extension` (.txt -> ECD text, .dat -> dat),
  /// else (.raw, or a stream without a name) by the EVT line of a '%' header ("% evt 3.0",
  /// "% format EVT3;..."). Throws std::runtime_error if the extension does not tell the format, and
  /// FormatError if a RAW header names no EVT 2.0/2.1/3.0 encoding or the header is corrupt.
  EventStreamReader(std::unique_ptr<ByteSource> bytes, std::optional<EventFormat> format, std::string_view extension,
                    std::size_t chunk_bytes = kReadChunkBytes);
  /// A finished file; the extension from its name. Also throws std::runtime_error naming the path if
  /// the file cannot be opened.
  explicit EventStreamReader(const std::filesystem::path& path, std::optional<EventFormat> format = {},
                             std::size_t chunk_bytes = kReadChunkBytes);

  /// Clears `out` and fills it with the events of the next chunk(s): at least one event unless the
  /// stream is at its end, when it returns false. On corrupt data it first returns the valid events
  /// decoded before the fault and throws the FormatError on the next call; after that it returns false.
  bool read(EventBatch& out);

  /// Sensor size from the header (EVT 2.0/3.0, dat), nullopt if there is none.
  [[nodiscard]] std::optional<SensorSize> geometry() const { return decoder_->geometry(); }
  [[nodiscard]] EventFormat format() const { return format_; }
  /// Words skipped and trigger events counted by the decoder so far.
  [[nodiscard]] DecodeCounts counts() const { return decoder_->counts(); }
  /// Progress: bytes read so far, and the source's size where known (else 0).
  [[nodiscard]] std::uint64_t bytes_read() const { return bytes_read_; }
  [[nodiscard]] std::uint64_t total_bytes() const { return bytes_->size(); }
  [[nodiscard]] const std::string& name() const { return bytes_->name(); }

 private:
  /// Reads the next chunk into chunk_; its size, 0 at the end of the stream.
  std::size_t read_chunk();

  std::unique_ptr<ByteSource> bytes_;
  std::uint64_t bytes_read_ = 0;
  std::vector<std::uint8_t> chunk_;
  EventFormat format_ = EventFormat::EcdText;
  std::unique_ptr<EventDecoder> decoder_;
  EventBatch pending_;                // events decoded while the header was parsed, not yet returned
  std::exception_ptr pending_error_;  // thrown by the next read()
  bool at_end_ = false;
};

}  // namespace evldt
