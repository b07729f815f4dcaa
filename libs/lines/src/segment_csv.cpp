#include "evldt/lines/segment_csv.hpp"

#include <algorithm>
#include <cinttypes>
#include <sstream>
#include <stdexcept>
#include <string>

namespace evldt {

void SegmentCsvWriter::write_step(Timestamp t, std::span<const TrackedLine> lines) {
  sorted_.clear();
  for (const TrackedLine& line : lines) sorted_.push_back(&line);
  std::sort(sorted_.begin(), sorted_.end(), [](const TrackedLine* a, const TrackedLine* b) { return a->id < b->id; });
  for (const TrackedLine* line : sorted_) {
    const Segment& s = line->segment;
    std::fprintf(output_.file(), "%" PRId64 ",%" PRIu64 ",%.3f,%.3f,%.3f,%.3f,%.4f,%s\n", t, line->id, static_cast<double>(s.q0.x()),
                 static_cast<double>(s.q0.y()), static_cast<double>(s.q1.x()), static_cast<double>(s.q1.y()),
                 static_cast<double>(line->score), status_name(line->status).data());
  }
  rows_ += sorted_.size();
}

namespace {

LineStatus parse_status(const std::string& text) {
  for (const LineStatus s : {LineStatus::Detected, LineStatus::GoodTrack, LineStatus::BadTrack}) {
    if (text == status_name(s)) return s;
  }
  throw std::invalid_argument("unknown status '" + text + "'");
}

}  // namespace

std::vector<SegmentRow> read_segment_csv(const std::filesystem::path& path) {
  std::vector<SegmentRow> rows;
  read_csv_rows(path, kSegmentCsvHeader, [&](const std::string& line) {
    std::istringstream fields(line);
    SegmentRow row;
    char c[7];
    float x0, y0, x1, y1;
    std::string status;
    if (!(fields >> row.t_us >> c[0] >> row.id >> c[1] >> x0 >> c[2] >> y0 >> c[3] >> x1 >> c[4] >> y1 >> c[5] >> row.score >>
          c[6]) ||
        std::count(c, c + 7, ',') != 7 || !std::getline(fields, status)) {
      throw std::invalid_argument("malformed row '" + line + "'");
    }
    row.status = parse_status(status);
    row.segment = {Point2(x0, y0), Point2(x1, y1)};
    rows.push_back(row);
  });
  return rows;
}

}  // namespace evldt
