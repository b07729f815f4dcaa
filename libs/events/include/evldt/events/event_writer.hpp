#pragma once
// Writing recordings: an encoder per format turns events into bytes, EventWriter puts them in a file.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string_view>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {

/// Turns events into the bytes of one format, in memory.
class EventEncoder {
 public:
  virtual ~EventEncoder() = default;

  /// Appends the file header (EVT 2.0/3.0 and dat carry the sensor size; ECD text has no header).
  virtual void write_header(std::vector<std::uint8_t>& out) const = 0;

  /// Appends the encoding of the batch. Throws std::invalid_argument, leaving the encoder and `out` as
  /// they were, if time goes backwards (within the batch or from the previous one), a time is negative,
  /// or a coordinate does not fit the format.
  virtual void encode(const EventBatch& batch, std::vector<std::uint8_t>& out) = 0;
};

/// Throws std::invalid_argument if the format cannot describe the sensor (EVT: up to 2048x2048).
std::unique_ptr<EventEncoder> make_encoder(EventFormat format, SensorSize sensor);

class EventWriter {
 public:
  /// Creates or truncates `path` and writes the header. Throws std::runtime_error naming the path if the
  /// file cannot be written, std::invalid_argument if the format cannot describe the sensor.
  EventWriter(const std::filesystem::path& path, EventFormat format, SensorSize sensor);
  /// Closes without throwing; call close() to learn about write errors.
  ~EventWriter();
  EventWriter(const EventWriter&) = delete;
  EventWriter& operator=(const EventWriter&) = delete;

  /// Events must be in non-decreasing time order, also across calls (else std::invalid_argument and
  /// nothing of the batch is written).
  void write(const EventBatch& batch);
  /// Flushes and closes; throws std::runtime_error naming the path on an IO error. Idempotent.
  void close();

 private:
  void check_stream(const char* doing) const;

  std::filesystem::path path_;
  std::unique_ptr<EventEncoder> encoder_;
  std::ofstream file_;
  std::vector<std::uint8_t> buffer_;
};

namespace detail {

// One factory per format source file; make_encoder picks among them.
std::unique_ptr<EventEncoder> make_ecd_text_encoder();
std::unique_ptr<EventEncoder> make_evt2_encoder(SensorSize sensor);
std::unique_ptr<EventEncoder> make_evt3_encoder(SensorSize sensor);
std::unique_ptr<EventEncoder> make_evt21_encoder(SensorSize sensor);
std::unique_ptr<EventEncoder> make_dat_encoder(SensorSize sensor);

/// Throws std::invalid_argument unless the batch's times are non-decreasing, starting from at least
/// `previous_time` (0 before the first event), and its coordinates are at most `max_coordinate`.
void check_encodable(const EventBatch& batch, Timestamp previous_time, int max_coordinate, std::string_view format);

inline void append_le16(std::uint16_t value, std::vector<std::uint8_t>& out) {
  out.push_back(static_cast<std::uint8_t>(value));
  out.push_back(static_cast<std::uint8_t>(value >> 8));
}
inline void append_le32(std::uint32_t value, std::vector<std::uint8_t>& out) {
  for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<std::uint8_t>(value >> shift));
}

/// The header lines of a RAW file of `encoding` ("EVT2", "EVT3", "EVT21"): "% evt X.0" (not for
/// EVT 2.1), "% format ENCODING;height=H;width=W", "% geometry WxH", "% end".
void write_raw_header(std::string_view encoding, SensorSize sensor, std::vector<std::uint8_t>& out);

}  // namespace detail
}  // namespace evldt
