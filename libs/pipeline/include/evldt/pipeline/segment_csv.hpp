#pragma once
// Segments over time as CSV: "t_us,id,x0,y0,x1,y1,score,status,normal_velocity,normal_velocity_std",
// one row per live segment per output step, rows of a step sorted by id. Coordinates are continuous
// image coordinates; velocities px/s (TrackedLine's). Files without the two velocity columns, as
// evldt wrote them before it estimated motion, are read too.

#include <filesystem>
#include <limits>
#include <span>
#include <vector>

#include "evldt/events/csv_file.hpp"
#include "evldt/lines/line_types.hpp"

namespace evldt {

inline constexpr const char* kSegmentCsvHeader = "t_us,id,x0,y0,x1,y1,score,status,normal_velocity,normal_velocity_std";
/// The header of a file without velocities.
inline constexpr const char* kSegmentCsvHeaderWithoutVelocity = "t_us,id,x0,y0,x1,y1,score,status";

class SegmentCsvWriter {
 public:
  /// Throws std::runtime_error naming the path if it cannot be created.
  explicit SegmentCsvWriter(const std::filesystem::path& path) : output_(path, kSegmentCsvHeader) {}

  void write_step(Timestamp t, std::span<const TrackedLine> lines);
  /// Flushes and checks for write errors (throws std::runtime_error).
  void close() { output_.close(); }
  [[nodiscard]] std::uint64_t rows() const { return rows_; }

 private:
  CsvOutput output_;
  std::vector<const TrackedLine*> sorted_;
  std::uint64_t rows_ = 0;
};

struct SegmentRow {
  Timestamp t_us = 0;
  std::uint64_t id = 0;
  Segment segment;
  float score = 0;
  LineStatus status = LineStatus::Detected;
  float normal_velocity = std::numeric_limits<float>::quiet_NaN();  ///< NaN: not known
  float normal_velocity_std = std::numeric_limits<float>::quiet_NaN();
};

/// Reads a whole segment CSV; throws std::runtime_error naming the file and line on malformed input.
std::vector<SegmentRow> read_segment_csv(const std::filesystem::path& path);

}  // namespace evldt
