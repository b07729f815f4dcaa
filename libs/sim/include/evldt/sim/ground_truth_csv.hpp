#pragma once
// Ground-truth segments over time as CSV: "t_us,gt_id,x0,y0,x1,y1", one row per visible edge piece
// per step (continuous image coordinates; see scarf_lattice.hpp).

#include <filesystem>
#include <span>
#include <vector>

#include "evldt/events/csv_file.hpp"
#include "evldt/sim/scene.hpp"

namespace evldt {

inline constexpr const char* kGroundTruthCsvHeader = "t_us,gt_id,x0,y0,x1,y1";

class GroundTruthCsvWriter {
 public:
  explicit GroundTruthCsvWriter(const std::filesystem::path& path) : output_(path, kGroundTruthCsvHeader) {}
  void write_step(Timestamp t, std::span<const GtSegment> segments);
  void close() { output_.close(); }  ///< throws std::runtime_error on a write error

 private:
  CsvOutput output_;
};

struct GroundTruthRow {
  Timestamp t_us = 0;
  GtSegment segment;
};

/// Throws std::runtime_error naming the file and line on malformed input.
std::vector<GroundTruthRow> read_ground_truth_csv(const std::filesystem::path& path);

}  // namespace evldt
