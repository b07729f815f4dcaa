#include "evldt/eval/plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace evldt {

namespace {

const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);
const cv::Scalar kIsoF(170, 215, 170);
const cv::Scalar kCurve(180, 90, 20);
const cv::Scalar kBest(30, 30, 220);
const cv::Scalar kBar(200, 150, 90);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kSmallText = 0.42;
constexpr double kLabelText = 0.55;
constexpr double kTitleText = 0.7;

enum class Align { Left, Centre, Right };

std::string formatted(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

/// Draws text with its baseline at y, aligned horizontally on x.
void put_text(cv::Mat& image, const std::string& text, int x, int y, double scale, const cv::Scalar& colour,
              Align align = Align::Left, int thickness = 1) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, thickness, &baseline);
  if (align == Align::Centre) x -= size.width / 2;
  if (align == Align::Right) x -= size.width;
  cv::putText(image, text, {x, y}, kFont, scale, colour, thickness, cv::LINE_AA);
}

/// putText cannot rotate, so the text is drawn upright on its own canvas, turned, and darkened into
/// the image centred on (x, y).
void put_vertical_text(cv::Mat& image, const std::string& text, int x, int y, double scale) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, 1, &baseline);
  cv::Mat upright(size.height + baseline + 4, size.width + 4, image.type(), kWhite);
  cv::putText(upright, text, {2, size.height + 2}, kFont, scale, kBlack, 1, cv::LINE_AA);
  cv::Mat turned;
  cv::rotate(upright, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect target = cv::Rect(x - turned.cols / 2, y - turned.rows / 2, turned.cols, turned.rows) &
                          cv::Rect(0, 0, image.cols, image.rows);
  if (target.size() != turned.size()) return;  // would not fit whole; the layout leaves room for it
  cv::Mat destination = image(target);
  cv::min(destination, turned, destination);
}

/// A step of 1, 2 or 5 times a power of ten that cuts [0, range] into at most max_ticks parts.
double nice_step(double range, int max_ticks) {
  const double raw = range / max_ticks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double multiple : {1.0, 2.0, 5.0}) {
    if (multiple * power >= raw) return multiple * power;
  }
  return 10.0 * power;
}

/// Maps data coordinates [0, x_max] x [0, y_max] onto a pixel rectangle, y up.
struct Axes {
  cv::Rect area;
  double x_max = 1;
  double y_max = 1;

  [[nodiscard]] cv::Point at(double x, double y) const {
    return {area.x + static_cast<int>(std::lround(x / x_max * area.width)),
            area.y + area.height - static_cast<int>(std::lround(y / y_max * area.height))};
  }
};

/// Grid lines and tick labels every step, the frame, and the axis names.
void draw_axes(cv::Mat& image, const Axes& axes, double x_step, double y_step, const char* tick_pattern,
               const std::string& x_name, const std::string& y_name) {
  const int x_ticks = static_cast<int>(std::floor(axes.x_max / x_step + 1e-9));
  for (int k = 0; k <= x_ticks; ++k) {
    const cv::Point bottom = axes.at(k * x_step, 0), top = axes.at(k * x_step, axes.y_max);
    cv::line(image, bottom, top, kGrid, 1);
    cv::line(image, bottom, bottom + cv::Point(0, 5), kBlack, 1);
    put_text(image, formatted(tick_pattern, k * x_step), bottom.x, bottom.y + 20, kSmallText, kBlack, Align::Centre);
  }
  const int y_ticks = static_cast<int>(std::floor(axes.y_max / y_step + 1e-9));
  for (int k = 0; k <= y_ticks; ++k) {
    const cv::Point left = axes.at(0, k * y_step), right = axes.at(axes.x_max, k * y_step);
    cv::line(image, left, right, kGrid, 1);
    cv::line(image, left, left - cv::Point(5, 0), kBlack, 1);
    put_text(image, formatted(tick_pattern, k * y_step), left.x - 8, left.y + 5, kSmallText, kBlack, Align::Right);
  }
  cv::rectangle(image, axes.area, kBlack, 1);
  put_text(image, x_name, axes.area.x + axes.area.width / 2, axes.area.y + axes.area.height + 48, kLabelText, kBlack,
           Align::Centre);
  put_vertical_text(image, y_name, axes.area.x - 58, axes.area.y + axes.area.height / 2, kLabelText);
}

cv::Mat blank_chart(const std::string& title) {
  cv::Mat image(kPlotHeight, kPlotWidth, CV_8UC3, kWhite);
  put_text(image, title, kPlotWidth / 2, 34, kTitleText, kBlack, Align::Centre, 2);
  return image;
}

void write_png(const std::filesystem::path& path, const cv::Mat& image) {
  bool written = false;
  try {
    written = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot write " + path.string() + ": " + e.what());
  }
  if (!written) throw std::runtime_error("cannot write " + path.string());
}

// Room around the plot area for the title, the tick labels and the axis names.
constexpr int kMarginLeft = 90;
constexpr int kMarginRight = 30;
constexpr int kMarginTop = 60;
constexpr int kMarginBottom = 75;

}  // namespace

void write_pr_curve_png(const std::filesystem::path& path, std::span<const PrPoint> points, const std::string& title) {
  cv::Mat image = blank_chart(title);
  // Square axes, so that equal precision and recall lie on the diagonal.
  const int side = std::min(kPlotWidth - kMarginLeft - kMarginRight, kPlotHeight - kMarginTop - kMarginBottom);
  const int left = kMarginLeft + (kPlotWidth - kMarginLeft - kMarginRight - side) / 2;
  const Axes axes{{left, kMarginTop, side, side}, 1.0, 1.0};
  draw_axes(image, axes, 0.1, 0.1, "%.1f", "Recall", "Precision");

  // Iso-F curves: P = F R / (2 R - F), visible for R >= F / (2 - F) where P <= 1.
  for (int tenth = 1; tenth <= 9; ++tenth) {
    const double f = tenth / 10.0;
    const double first_recall = f / (2.0 - f);
    std::vector<cv::Point> curve;
    for (int i = 0; i <= 100; ++i) {
      const double recall = first_recall + (1.0 - first_recall) * i / 100.0;
      curve.push_back(axes.at(recall, f * recall / (2.0 * recall - f)));
    }
    cv::polylines(image, curve, false, kIsoF, 1, cv::LINE_AA);
    put_text(image, formatted("F=%.1f", f), curve.back().x - 4, curve.back().y - 4, kSmallText * 0.85, kIsoF,
             Align::Right);
  }

  std::vector<PrPoint> shown;
  for (const PrPoint& p : points) {
    if (std::isfinite(p.precision) && std::isfinite(p.recall)) shown.push_back(p);
  }
  if (shown.empty()) {
    put_text(image, "no data", axes.area.x + side / 2, axes.area.y + side / 2, kLabelText, kBlack, Align::Centre);
    write_png(path, image);
    return;
  }
  std::stable_sort(shown.begin(), shown.end(),
                   [](const PrPoint& a, const PrPoint& b) { return a.threshold < b.threshold; });
  const auto pixel_of = [&axes](const PrPoint& p) {
    return axes.at(std::clamp(p.recall, 0.0, 1.0), std::clamp(p.precision, 0.0, 1.0));
  };
  std::vector<cv::Point> curve;
  for (const PrPoint& p : shown) curve.push_back(pixel_of(p));
  cv::polylines(image, curve, false, kCurve, 2, cv::LINE_AA);

  const PrPoint* best = &shown.front();
  for (const PrPoint& p : shown) {
    if (p.f > best->f) best = &p;
  }
  for (const PrPoint& p : shown) {
    const cv::Point at = pixel_of(p);
    cv::circle(image, at, 4, &p == best ? kBest : kCurve, cv::FILLED, cv::LINE_AA);
    put_text(image, formatted("%.3g", p.threshold), at.x + 6, at.y - 6, kSmallText, kBlack);
  }
  put_text(image, formatted("best F = %.3f", best->f) + formatted(" at threshold %.3g", best->threshold),
           axes.area.x + 8, axes.area.y + side - 10, kSmallText, kBest);
  write_png(path, image);
}

void write_histogram_png(const std::filesystem::path& path, const std::vector<std::uint64_t>& counts,
                         double bin_width_ms, const std::string& title) {
  if (!std::isfinite(bin_width_ms) || bin_width_ms <= 0) {
    throw std::invalid_argument("histogram bin width must be finite and > 0, got " + std::to_string(bin_width_ms));
  }
  cv::Mat image = blank_chart(title);
  const cv::Rect area(kMarginLeft, kMarginTop, kPlotWidth - kMarginLeft - kMarginRight,
                      kPlotHeight - kMarginTop - kMarginBottom);
  const std::uint64_t highest = counts.empty() ? 0 : *std::max_element(counts.begin(), counts.end());
  const double x_range = counts.empty() ? bin_width_ms : bin_width_ms * static_cast<double>(counts.size());
  // Whole counts on the y axis, topped up to a whole step so the highest bar is below the frame.
  const double y_step = std::max(1.0, nice_step(std::max(1.0, static_cast<double>(highest)), 8));
  const double y_max = y_step * std::ceil(std::max(1.0, static_cast<double>(highest)) / y_step);
  const double x_step = nice_step(x_range, 10);
  const Axes axes{area, x_range, y_max};
  draw_axes(image, axes, x_step, y_step, "%g", "time [ms]", "count");

  if (highest == 0) {
    put_text(image, "no data", area.x + area.width / 2, area.y + area.height / 2, kLabelText, kBlack, Align::Centre);
  }
  for (std::size_t k = 0; k < counts.size(); ++k) {
    if (counts[k] == 0) continue;
    const cv::Point top_left = axes.at(static_cast<double>(k) * bin_width_ms, static_cast<double>(counts[k]));
    cv::Point bottom_right = axes.at(static_cast<double>(k + 1) * bin_width_ms, 0);
    bottom_right.x = std::max(bottom_right.x, top_left.x + 1);  // narrow bins still show
    cv::rectangle(image, cv::Rect(top_left, bottom_right), kBar, cv::FILLED);
    if (bottom_right.x - top_left.x >= 4) cv::rectangle(image, cv::Rect(top_left, bottom_right), kCurve, 1);
  }
  cv::rectangle(image, area, kBlack, 1);
  write_png(path, image);
}

}  // namespace evldt
