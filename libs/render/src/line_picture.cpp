#include "evldt/render/line_picture.hpp"

namespace evldt {

void LinePicture::draw(SensorSize sensor, std::span<const std::uint16_t> surface, std::span<const TrackedLine> segments,
                       std::span<const TrackedLine> whole_lines, const RenderOptions& options, cv::Mat& canvas) {
  ids_.clear();
  for (const TrackedLine& line : segments) ids_.push_back(line.id);
  segment_ids_.label(ids_, labels_);
  render_scene(sensor, surface, segments, options, canvas, labels_);
  ids_.clear();
  for (const TrackedLine& line : whole_lines) ids_.push_back(line.id);
  whole_line_ids_.label(ids_, labels_);
  draw_whole_lines(whole_lines, options, canvas, labels_);
}

}  // namespace evldt
