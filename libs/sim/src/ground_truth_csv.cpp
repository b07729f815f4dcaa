#include "evldt/sim/ground_truth_csv.hpp"

#include <cinttypes>
#include <sstream>
#include <stdexcept>
#include <string>

namespace evldt {

void GroundTruthCsvWriter::write_step(Timestamp t, std::span<const GtSegment> segments) {
  for (const GtSegment& s : segments) {
    std::fprintf(output_.file(), "%" PRId64 ",%d,%.3f,%.3f,%.3f,%.3f\n", t, s.gt_id, s.a.x(), s.a.y(), s.b.x(),
                 s.b.y());
  }
}

std::vector<GroundTruthRow> read_ground_truth_csv(const std::filesystem::path& path) {
  std::vector<GroundTruthRow> rows;
  read_csv_rows(path, kGroundTruthCsvHeader, [&](const std::string& line) {
    std::istringstream fields(line);
    GroundTruthRow row;
    char c[5];
    double x0, y0, x1, y1;
    if (!(fields >> row.t_us >> c[0] >> row.segment.gt_id >> c[1] >> x0 >> c[2] >> y0 >> c[3] >> x1 >> c[4] >> y1) ||
        std::string(c, 5) != ",,,,," || !(fields >> std::ws).eof()) {
      throw std::invalid_argument("malformed row '" + line + "'");
    }
    row.segment.a = {x0, y0};
    row.segment.b = {x1, y1};
    rows.push_back(row);
  });
  return rows;
}

}  // namespace evldt
