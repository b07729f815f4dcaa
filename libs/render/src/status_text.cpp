#include "evldt/render/status_text.hpp"

#include <opencv2/imgproc.hpp>

namespace evldt {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.45;
constexpr int kOutline = 3;     // px: the dark outline drawn under the white text
constexpr int kLeft = 6;        // px from the picture's left edge
constexpr int kRowHeight = 18;  // px

int text_width(const std::string& text) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, kFontScale, kOutline, &baseline).width;
}

}  // namespace

std::vector<std::string> wrap_fields(std::span<const std::string> fields, int width_px) {
  const int room = width_px - 2 * kLeft;
  std::vector<std::string> lines;
  for (const std::string& field : fields) {
    if (!lines.empty() && text_width(lines.back() + "  " + field) <= room) {
      lines.back() += "  " + field;
    } else {
      lines.push_back(field);
    }
  }
  return lines;
}

int put_text_lines(cv::Mat& canvas, std::span<const std::string> lines, int row) {
  for (const std::string& line : lines) {
    const cv::Point origin(kLeft, 16 + kRowHeight * row++);
    cv::putText(canvas, line, origin, kFont, kFontScale, cv::Scalar(0, 0, 0), kOutline, cv::LINE_AA);
    cv::putText(canvas, line, origin, kFont, kFontScale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return row;
}

}  // namespace evldt
