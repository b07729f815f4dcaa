#include "evldt/render/scene_renderer.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <string>

namespace evldt {

cv::Scalar status_colour(LineStatus status) {
  switch (status) {
    case LineStatus::Detected: return {0, 220, 255};   // yellow
    case LineStatus::GoodTrack: return {80, 220, 60};  // green
    case LineStatus::BadTrack: return {40, 40, 230};   // red
  }
  return {255, 255, 255};
}

void render_scene(SensorSize sensor, std::span<const std::uint16_t> surface, std::span<const TrackedLine> lines,
                  const RenderOptions& options, cv::Mat& canvas) {
  const int scale = std::max(1, options.scale);
  cv::Mat grey(sensor.height, sensor.width, CV_8UC1, cv::Scalar(0));
  if (surface.size() == static_cast<std::size_t>(sensor.width) * sensor.height) {
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

  // Continuous coordinates -> OpenCV pixel-centre coordinates, drawn with 4 fractional bits.
  constexpr int kShift = 4;
  auto to_canvas = [&](const Point2& p) {
    return cv::Point(static_cast<int>(std::lround(p.x() * static_cast<float>(scale * (1 << kShift)) - (1 << kShift) / 2.0f)),
                     static_cast<int>(std::lround(p.y() * static_cast<float>(scale * (1 << kShift)) - (1 << kShift) / 2.0f)));
  };
  const int thickness = std::max(1, scale / 2);
  for (const TrackedLine& line : lines) {
    const cv::Scalar colour = status_colour(line.status);
    cv::line(canvas, to_canvas(line.segment.q0), to_canvas(line.segment.q1), colour, thickness, cv::LINE_AA, kShift);
    if (options.show_ids) {
      const Point2 c = line.segment.centre();
      cv::putText(canvas, std::to_string(line.id), cv::Point(static_cast<int>(c.x() * static_cast<float>(scale)) + 3, static_cast<int>(c.y() * static_cast<float>(scale))),
                  cv::FONT_HERSHEY_PLAIN, 0.8, colour, 1, cv::LINE_AA);
    }
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

}  // namespace evldt
