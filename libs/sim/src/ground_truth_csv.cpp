#include "evldt/sim/ground_truth_csv.hpp"

#include <cinttypes>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace evldt {

GroundTruthCsvWriter::GroundTruthCsvWriter(const std::filesystem::path& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) throw std::runtime_error("cannot create " + path.string());
  std::fprintf(file_, "%s\n", kGroundTruthCsvHeader);
}

GroundTruthCsvWriter::~GroundTruthCsvWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void GroundTruthCsvWriter::write_step(Timestamp t, std::span<const GtSegment> segments) {
  for (const GtSegment& s : segments) {
    std::fprintf(file_, "%" PRId64 ",%d,%.3f,%.3f,%.3f,%.3f\n", t, s.gt_id, s.a.x(), s.a.y(), s.b.x(), s.b.y());
  }
}

void GroundTruthCsvWriter::close() {
  if (file_ == nullptr) return;
  const bool failed = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (failed || close_failed) throw std::runtime_error("error writing " + path_.string());
}

std::vector<GroundTruthRow> read_ground_truth_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  std::vector<GroundTruthRow> rows;
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1) {
      if (line != kGroundTruthCsvHeader) throw std::runtime_error(path.string() + ":1: not a ground-truth CSV (header '" + line + "')");
      continue;
    }
    if (line.empty()) continue;
    std::istringstream fields(line);
    GroundTruthRow row;
    char c[5];
    double x0, y0, x1, y1;
    if (!(fields >> row.t_us >> c[0] >> row.segment.gt_id >> c[1] >> x0 >> c[2] >> y0 >> c[3] >> x1 >> c[4] >> y1) ||
        std::string(c, 5) != ",,,,," || !(fields >> std::ws).eof()) {
      throw std::runtime_error(path.string() + ":" + std::to_string(number) + ": malformed row '" + line + "'");
    }
    row.segment.a = {x0, y0};
    row.segment.b = {x1, y1};
    rows.push_back(row);
  }
  return rows;
}

}  // namespace evldt
