#include "evldt/render/scene_renderer.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <string>

#include "evldt/lines/normal_motion.hpp"

namespace evldt {

namespace {

// Continuous coordinates -> OpenCV pixel-centre coordinates, drawn with 4 fractional bits.
constexpr int kShift = 4;
cv::Point to_canvas(const Point2& p, int scale) {
  return cv::Point(
      static_cast<int>(std::lround(p.x() * static_cast<float>(scale * (1 << kShift)) - (1 << kShift) / 2.0f)),
      static_cast<int>(std::lround(p.y() * static_cast<float>(scale * (1 << kShift)) - (1 << kShift) / 2.0f)));
}

void draw_labelled(cv::Mat& canvas, const TrackedLine& line, const cv::Scalar& colour, int thickness, int scale,
                   bool show_label, std::uint64_t label) {
  cv::line(canvas, to_canvas(line.segment.q0, scale), to_canvas(line.segment.q1, scale), colour, thickness, cv::LINE_AA,
           kShift);
  if (!show_label) return;
  const Point2 c = line.segment.centre();
  cv::putText(canvas, std::to_string(label),
              cv::Point(static_cast<int>(c.x() * static_cast<float>(scale)) + 3,
                        static_cast<int>(c.y() * static_cast<float>(scale))),
              cv::FONT_HERSHEY_PLAIN, 0.8, colour, 1, cv::LINE_AA);
}

}  // namespace

cv::Scalar status_colour(LineStatus status) {
  switch (status) {
    case LineStatus::Detected:
      return {0, 220, 255};  // yellow
    case LineStatus::GoodTrack:
      return {80, 220, 60};  // green
    case LineStatus::BadTrack:
      return {40, 40, 230};  // red
  }
  return {255, 255, 255};
}

const Layer* find_layer(int key) {
  const auto* layer = std::ranges::find(kLayers, key, [](const Layer& l) { return static_cast<int>(l.key); });
  return layer == kLayers.end() ? nullptr : layer;
}

bool toggle_layer(RenderOptions& options, int key) {
  const Layer* layer = find_layer(key);
  if (layer == nullptr) return false;
  options.*(layer->shown) = !(options.*(layer->shown));
  return true;
}

std::vector<std::string> layer_key_help() {
  std::vector<std::string> fields;
  fields.reserve(std::size(kLayers) + 1);
  for (const Layer& layer : kLayers)
    fields.push_back(std::string(fields.empty() ? "keys: " : "") + layer.key + " " + layer.name);
  fields.emplace_back("q quit");
  return fields;
}

void render_scene(SensorSize sensor, std::span<const std::uint16_t> surface, std::span<const TrackedLine> lines,
                  const RenderOptions& options, cv::Mat& canvas, std::span<const std::uint32_t> labels) {
  const int scale = std::max(1, options.scale);
  cv::Mat grey(sensor.height, sensor.width, CV_8UC1, cv::Scalar(0));
  if (options.show_events && surface.size() == static_cast<std::size_t>(sensor.width) * sensor.height) {
    for (int y = 0; y < sensor.height; ++y) {
      auto* row = grey.ptr<std::uint8_t>(y);
      for (int x = 0; x < sensor.width; ++x) {
        const std::uint16_t count = surface[static_cast<std::size_t>(y) * sensor.width + x];
        row[x] = count == 0 ? 0 : static_cast<std::uint8_t>(std::min(255, 110 + 40 * count));
      }
    }
  }
  cv::Mat bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  cv::resize(bgr, canvas, cv::Size(sensor.width * scale, sensor.height * scale), 0, 0, cv::INTER_NEAREST);

  if (options.show_grid && options.grid_block_size > 0) {
    // Block borders lie on the lattice lines b/2 + k b (scarf_lattice.hpp).
    const cv::Scalar grid(90, 60, 40);
    const int b = options.grid_block_size, half = b / 2;
    for (int x = half; x <= sensor.width; x += b)
      cv::line(canvas, {x * scale, 0}, {x * scale, canvas.rows - 1}, grid, 1);
    for (int y = half; y <= sensor.height; y += b)
      cv::line(canvas, {0, y * scale}, {canvas.cols - 1, y * scale}, grid, 1);
  }
  const int thickness = std::max(1, scale / 2);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const TrackedLine& line = lines[i];
    const bool bad = line.status == LineStatus::BadTrack;
    if (bad ? !options.show_bad_tracks : !options.show_segments) continue;
    draw_labelled(canvas, line, status_colour(line.status), thickness, scale, options.show_segment_ids,
                  i < labels.size() ? labels[i] : line.id);
  }
}

void draw_masked_pixels(SensorSize sensor, std::span<const std::int32_t> pixels, int scale, cv::Mat& canvas) {
  scale = std::max(1, scale);
  const std::int64_t count = static_cast<std::int64_t>(sensor.width) * sensor.height;
  for (const std::int32_t pixel : pixels) {
    if (pixel < 0 || pixel >= count) continue;
    const cv::Point centre((pixel % sensor.width) * scale + scale / 2, (pixel / sensor.width) * scale + scale / 2);
    cv::circle(canvas, centre, 2 + 2 * scale, cv::Scalar(255, 0, 255), 1, cv::LINE_AA);
  }
}

void draw_whole_lines(std::span<const TrackedLine> lines, const RenderOptions& options, cv::Mat& canvas,
                      std::span<const std::uint32_t> labels) {
  if (!options.show_whole_lines) return;
  const int scale = std::max(1, options.scale);
  const cv::Scalar cyan(230, 210, 40), orange(0, 140, 255);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    draw_labelled(canvas, lines[i], cyan, std::max(2, scale), scale, options.show_whole_line_ids,
                  i < labels.size() ? labels[i] : lines[i].id);
    if (!options.show_motion) continue;
    const Segment arrow = motion_arrow(lines[i].segment, lines[i].normal_velocity);
    if (!((arrow.q1 - arrow.q0).norm() >= 1.0f)) continue;  // still, or not known
    const auto at = [&](Point2 p) {
      return cv::Point2f(p.x() * static_cast<float>(scale), p.y() * static_cast<float>(scale));
    };
    cv::arrowedLine(canvas, at(arrow.q0), at(arrow.q1), orange, std::max(1, scale / 2), cv::LINE_AA, 0, 0.3);
  }
}

}  // namespace evldt
