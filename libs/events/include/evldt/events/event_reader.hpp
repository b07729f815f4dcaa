#pragma once
// Reading a recording file chunk by chunk, never the whole file at once.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {

class EventFileReader {
 public:
  /// Opens the file and parses its header. The format is `format` if given, else guessed from the name:
  /// .txt -> ECD text, .dat -> dat, .raw -> EVT 2.0 or 3.0 as the header says ("% evt 3.0",
  /// "% format EVT3;..."). Throws std::runtime_error naming the path if the file cannot be opened or its
  /// name does not tell the format, FormatError if a .raw header names no EVT 2.0/3.0 encoding or the
  /// header is corrupt.
  explicit EventFileReader(const std::filesystem::path& path, std::optional<EventFormat> format = {},
                           std::size_t chunk_bytes = std::size_t{1} << 20);

  /// Clears `out` and fills it with the events of the next chunk(s): at least one event unless the file
  /// is at its end, when it returns false. On corrupt data it first returns the valid events decoded
  /// before the fault and throws the FormatError on the next call; after that it returns false.
  bool read(EventBatch& out);

  /// Sensor size from the header (EVT 2.0/3.0, dat), nullopt if there is none.
  [[nodiscard]] std::optional<SensorSize> geometry() const { return decoder_->geometry(); }
  [[nodiscard]] EventFormat format() const { return format_; }
  /// Words skipped and trigger events counted by the decoder so far.
  [[nodiscard]] DecodeCounts counts() const { return decoder_->counts(); }
  /// Progress: bytes read from the file so far, and its size.
  [[nodiscard]] std::uint64_t bytes_read() const { return bytes_read_; }
  [[nodiscard]] std::uint64_t file_size() const { return file_size_; }

 private:
  /// Reads the next chunk into chunk_; its size, 0 at the end of the file.
  std::size_t read_chunk();

  std::string source_;
  std::ifstream file_;
  std::uint64_t file_size_ = 0;
  std::uint64_t bytes_read_ = 0;
  std::vector<std::uint8_t> chunk_;
  EventFormat format_ = EventFormat::EcdText;
  std::unique_ptr<EventDecoder> decoder_;
  EventBatch pending_;                // events decoded while the header was parsed, not yet returned
  std::exception_ptr pending_error_;  // thrown by the next read()
  bool at_end_ = false;
};

}  // namespace evldt
