#include "evldt/eval/plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "evldt/media/media.hpp"

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
    written = media::write_image(path.string(), image);
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
  curve.reserve(shown.size());
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

void write_id_timeline_png(const std::filesystem::path& path, std::span<const GroundTruthLineTrack> lines,
                           const std::string& title) {
  std::vector<const GroundTruthLineTrack*> shown;
  for (const GroundTruthLineTrack& line : lines) {
    if (!line.owners.empty()) shown.push_back(&line);
  }
  if (shown.size() > kTimelineMaxLines) {
    std::stable_sort(shown.begin(), shown.end(),
                     [](const auto* a, const auto* b) { return a->visible_steps > b->visible_steps; });
    shown.resize(kTimelineMaxLines);
    std::stable_sort(shown.begin(), shown.end(),
                     [](const auto* a, const auto* b) { return a->owners.front().t_us < b->owners.front().t_us; });
  }
  cv::Mat image = blank_chart(title);
  const cv::Rect area(kMarginLeft, kMarginTop, kPlotWidth - kMarginLeft - kMarginRight,
                      kPlotHeight - kMarginTop - kMarginBottom);
  put_text(image,
           formatted("%.0f", static_cast<double>(shown.size())) + " of " +
               formatted("%.0f", static_cast<double>(lines.size())) +
               " true lines; colour: predicted id, grey: none, tick: id switch",
           kPlotWidth / 2, 52, kSmallText, kBlack, Align::Centre);
  if (shown.empty()) {
    put_text(image, "no data", area.x + area.width / 2, area.y + area.height / 2, kLabelText, kBlack, Align::Centre);
    cv::rectangle(image, area, kBlack, 1);
    write_png(path, image);
    return;
  }
  Timestamp first = shown.front()->owners.front().t_us, last = first;
  for (const auto* line : shown) {
    first = std::min(first, line->owners.front().t_us);
    last = std::max(last, line->owners.back().t_us);
  }
  const double seconds = std::max(1e-3, static_cast<double>(last - first) * 1e-6);
  const double row_height = static_cast<double>(area.height) / static_cast<double>(shown.size());
  const Axes axes{area, seconds, static_cast<double>(shown.size())};
  const double x_step = nice_step(seconds, 10);
  for (int k = 0; k <= static_cast<int>(std::floor(seconds / x_step + 1e-9)); ++k) {
    const cv::Point bottom = axes.at(k * x_step, 0);
    cv::line(image, bottom, axes.at(k * x_step, axes.y_max), kGrid, 1);
    put_text(image, formatted("%g", k * x_step), bottom.x, bottom.y + 20, kSmallText, kBlack, Align::Centre);
  }
  put_text(image, "time [s]", area.x + area.width / 2, area.y + area.height + 48, kLabelText, kBlack, Align::Centre);
  const auto x_of = [&](Timestamp t) { return axes.at(static_cast<double>(t - first) * 1e-6, 0).x; };
  const auto colour_of = [](std::uint64_t id) {
    // A fixed hue per id (Fibonacci hashing spreads consecutive ids), saturated and mid-bright.
    const double hue = static_cast<double>((id * 0x9E3779B97F4A7C15ull) >> 40) / static_cast<double>(1ull << 24);
    cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue * 180.0, 200, 210)), bgr;
    cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
    return cv::Scalar(c[0], c[1], c[2]);
  };
  const int label_every = static_cast<int>(std::ceil(14.0 / row_height));
  for (std::size_t row = 0; row < shown.size(); ++row) {
    const GroundTruthLineTrack& line = *shown[row];
    const int top = area.y + static_cast<int>(std::lround(static_cast<double>(row) * row_height));
    const int bottom = area.y + static_cast<int>(std::lround(static_cast<double>(row + 1) * row_height)) - 1;
    const int inner_top = row_height >= 4 ? top + 1 : top;
    for (std::size_t k = 0; k < line.owners.size(); ++k) {
      const LineOwnerStep& o = line.owners[k];
      // A step reaches to the next one of the line, or one spacing on at its end.
      const Timestamp next = k + 1 < line.owners.size() ? line.owners[k + 1].t_us
                             : k > 0                    ? o.t_us + (o.t_us - line.owners[k - 1].t_us)
                                                        : o.t_us + 1;
      const int x0 = x_of(o.t_us), x1 = std::max(x0 + 1, x_of(next));
      cv::rectangle(image, cv::Rect(cv::Point(x0, inner_top), cv::Point(x1, bottom + 1)),
                    o.matched ? colour_of(o.id) : kGrid, cv::FILLED);
    }
    std::uint64_t representative = 0;
    bool has_representative = false;
    for (const LineOwnerStep& o : line.owners) {
      if (!o.matched) continue;
      if (has_representative && o.id != representative) {
        cv::line(image, {x_of(o.t_us), top}, {x_of(o.t_us), bottom}, kBlack, 1);
      }
      representative = o.id;
      has_representative = true;
    }
    if (static_cast<int>(row) % label_every == 0) {
      put_text(image, formatted("line %.0f", static_cast<double>(line.gt_id)), area.x - 6, (top + bottom) / 2 + 4,
               kSmallText * 0.9, kBlack, Align::Right);
    }
  }
  cv::rectangle(image, area, kBlack, 1);
  write_png(path, image);
}

}  // namespace evldt
