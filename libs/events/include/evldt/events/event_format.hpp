#pragma once
// Recording formats evldt reads and writes, and the error every decoder reports.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace evldt {

enum class EventFormat {
  EcdText,         ///< Event Camera Dataset events.txt: "t x y p" per line, t in seconds, p in {0,1}
  Evt2,            ///< Prophesee RAW EVT 2.0 (32-bit words, '%' text header)
  Evt3,            ///< Prophesee RAW EVT 3.0 (16-bit words, '%' text header)
  Evt21,           ///< Prophesee RAW EVT 2.1 (64-bit vectorised words, '%' text header)
  Dat,             ///< Prophesee .dat CD events (8-byte records, '%' text header)
  Aedat2,          ///< jAER AEDAT 2.0 (big-endian 8-byte address/time records, '#' text header); read only
  Aedat31,         ///< cAER AEDAT 3.1 (packets of typed events, '#' text header); read only
  Aedat31Network,  ///< cAER / libcaer's AEDAT 3.1 network stream: a 20-byte network header, then packets; read only
  EventStream,     ///< Event Stream .es 2.x, DVS and ATIS (time deltas in bytes); read only
};

/// "ecd", "evt2", "evt3", "evt21", "dat", "aedat2", "aedat31", "es" -> format; nullopt for anything else.
std::optional<EventFormat> parse_event_format(std::string_view name);
std::string_view format_name(EventFormat format);

/// Corrupt or truncated input. The message names the file (when known) and the byte offset.
class FormatError : public std::runtime_error {
 public:
  FormatError(std::string source, std::uint64_t byte_offset, const std::string& reason);
  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] std::uint64_t byte_offset() const { return byte_offset_; }

 private:
  std::string source_;
  std::uint64_t byte_offset_;
};

}  // namespace evldt
