#include "evldt/pipeline/segment_csv.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

namespace evldt {

void SegmentCsvWriter::write_step(Timestamp t, std::span<const TrackedLine> lines) {
  sorted_.clear();
  for (const TrackedLine& line : lines) sorted_.push_back(&line);
  std::sort(sorted_.begin(), sorted_.end(), [](const TrackedLine* a, const TrackedLine* b) { return a->id < b->id; });
  // The row as printf's "%lld,%llu,%.3f,%.3f,%.3f,%.3f,%.4f,%s,%.1f,%.1f" writes it (std::to_chars with a
  // precision is specified so), at a fifth of its cost: printf's float formatting was a tenth of a
  // whole evldt-offline run on monitor-hd.
  char row[512];  // room for any float in fixed notation (at most 45 characters) in each field
  for (const TrackedLine* line : sorted_) {
    const Segment& s = line->segment;
    char* at = row;
    char* const end = row + sizeof row - 1;  // a field leaves room for the separator after it
    const auto put = [&](auto value, auto... format) {
      at = std::to_chars(at, end, value, format...).ptr;
      *at++ = ',';
    };
    put(t);
    put(line->id);
    for (const float coordinate : {s.q0.x(), s.q0.y(), s.q1.x(), s.q1.y()})
      put(static_cast<double>(coordinate), std::chars_format::fixed, 3);
    put(static_cast<double>(line->score), std::chars_format::fixed, 4);
    const std::string_view status = status_name(line->status);
    at = std::copy(status.begin(), status.end(), at);
    *at++ = ',';
    put(static_cast<double>(line->normal_velocity), std::chars_format::fixed, 1);
    at = std::to_chars(at, end, static_cast<double>(line->normal_velocity_std), std::chars_format::fixed, 1).ptr;
    *at++ = '\n';
    std::fwrite(row, 1, static_cast<std::size_t>(at - row), output_.file());
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
  const std::string_view headers[] = {kSegmentCsvHeader, kSegmentCsvHeaderWithoutVelocity};
  read_csv_rows(path, headers, [&](std::size_t header, const std::string& line) {
    std::istringstream fields(line);
    SegmentRow row;
    char c[7];
    float x0, y0, x1, y1;
    std::string status;
    const bool with_velocity = header == 0;
    if (!(fields >> row.t_us >> c[0] >> row.id >> c[1] >> x0 >> c[2] >> y0 >> c[3] >> x1 >> c[4] >> y1 >> c[5] >>
          row.score >> c[6]) ||
        std::count(c, c + 7, ',') != 7 || !std::getline(fields, status, with_velocity ? ',' : '\n')) {
      throw std::invalid_argument("malformed row '" + line + "'");
    }
    if (with_velocity) {
      char comma = 0;
      if (!(fields >> row.normal_velocity >> comma >> row.normal_velocity_std) || comma != ',' ||
          !(fields >> std::ws).eof()) {
        throw std::invalid_argument("malformed row '" + line + "'");
      }
    }
    row.status = parse_status(status);
    row.segment = {Point2(x0, y0), Point2(x1, y1)};
    rows.push_back(row);
  });
  return rows;
}

}  // namespace evldt
