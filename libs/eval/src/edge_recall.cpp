#include "evldt/eval/edge_recall.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "evldt/eval/line_heatmap.hpp"
#include "evldt/media/media.hpp"

namespace evldt {

namespace {

float measure_of(const EdgeStep& step, EdgeMeasure measure) {
  switch (measure) {
    case EdgeMeasure::NormalSpeed:
      return step.normal_speed_px_s;
    case EdgeMeasure::Length:
      return step.length_px;
    case EdgeMeasure::ParallelGap:
      return step.parallel_gap_px;
  }
  return std::numeric_limits<float>::quiet_NaN();
}

/// Distance to the nearest piece of another line that is parallel to `piece` within the limit and
/// overlaps it along its length.
float parallel_gap(const Segment& piece, std::size_t self, std::span<const Segment> truth,
                   std::span<const std::uint64_t> ids) {
  const float length = piece.length();
  const Point2 unit = (piece.q1 - piece.q0) / length;
  const Point2 normal(-unit.y(), unit.x());
  const Point2 middle = 0.5f * (piece.q0 + piece.q1);
  const float max_sine = std::sin(EdgeRecall::kParallelDegrees * std::numbers::pi_v<float> / 180.0f);
  float gap = std::numeric_limits<float>::infinity();
  for (std::size_t j = 0; j < truth.size(); ++j) {
    if (j == self || ids[j] == ids[self]) continue;
    const float other_length = truth[j].length();
    if (!(other_length > 0)) continue;
    const Point2 other_unit = (truth[j].q1 - truth[j].q0) / other_length;
    if (std::abs(cross2(unit, other_unit)) > max_sine) continue;
    const Point2 other_middle = 0.5f * (truth[j].q0 + truth[j].q1);
    if (std::abs((other_middle - middle).dot(unit)) > 0.5f * (length + other_length)) continue;
    gap = std::min(gap, std::abs((other_middle - middle).dot(normal)));
  }
  return gap;
}

}  // namespace

void EdgeRecall::add_step(Timestamp t, std::span<const Segment> truth, std::span<const std::uint64_t> ids,
                          std::span<const Segment> predicted, std::span<const std::uint8_t> matched_map) {
  if (picture_at_us_ && !picture_ && t >= *picture_at_us_) {
    picture_ = Picture{t,
                       {truth.begin(), truth.end()},
                       {predicted.begin(), predicted.end()},
                       {matched_map.begin(), matched_map.end()}};
  }
  std::unordered_map<std::uint64_t, Seen> current;
  const auto width = static_cast<std::uint32_t>(sensor_.width);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Segment& piece = truth[i];
    const float length = piece.length();
    if (!(length > 0)) continue;
    EdgeStep step{t, ids[i], length, std::numeric_limits<float>::quiet_NaN(), parallel_gap(piece, i, truth, ids), 0, 0};
    // The speed of the line across itself: how far the previous step's piece lies from it now.
    const Point2 normal = Point2(-(piece.q1 - piece.q0).y(), (piece.q1 - piece.q0).x()) / length;
    if (const auto seen = previous_.find(ids[i]); seen != previous_.end() && t > seen->second.t_us) {
      const Point2 before = 0.5f * (seen->second.first_piece.q0 + seen->second.first_piece.q1);
      step.normal_speed_px_s =
          std::abs((before - piece.q0).dot(normal)) / (static_cast<float>(t - seen->second.t_us) * 1e-6f);
    }
    current.try_emplace(ids[i], Seen{t, piece});
    pixels_.clear();
    for_each_segment_sample(piece, sensor_, [&](int x, int y) {
      pixels_.push_back(static_cast<std::uint32_t>(y) * width + static_cast<std::uint32_t>(x));
    });
    std::sort(pixels_.begin(), pixels_.end());
    pixels_.erase(std::unique(pixels_.begin(), pixels_.end()), pixels_.end());
    step.pixels = static_cast<std::uint32_t>(pixels_.size());
    for (const std::uint32_t p : pixels_) step.matched += matched_map[p] != 0 ? 1 : 0;
    steps_.push_back(step);
  }
  previous_ = std::move(current);
}

std::vector<EdgeRecallBin> bin_edge_recall(std::span<const EdgeStep> steps, EdgeMeasure measure,
                                           std::span<const double> edges) {
  std::vector<EdgeRecallBin> bins;
  for (std::size_t b = 0; b + 1 < edges.size(); ++b) bins.push_back({edges[b], edges[b + 1], 0, 0});
  for (const EdgeStep& step : steps) {
    const double value = measure_of(step, measure);
    if (std::isnan(value)) continue;
    for (EdgeRecallBin& bin : bins) {
      if (value < bin.lo || value >= bin.hi) continue;
      bin.pixels += step.pixels;
      bin.matched += step.matched;
      break;
    }
  }
  return bins;
}

std::string edge_recall_tables(std::span<const EdgeStep> steps) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  struct Table {
    const char* title;
    EdgeMeasure measure;
    std::vector<double> edges;
  };
  const Table tables[] = {
      {"speed across itself, px/s", EdgeMeasure::NormalSpeed, {0, 2, 5, 10, 20, 40, 80, 160, 320, kInf}},
      {"length, px", EdgeMeasure::Length, {0, 8, 16, 24, 40, 64, 128, kInf}},
      {"nearest parallel edge, px", EdgeMeasure::ParallelGap, {0, 4, 8, 12, 16, 24, 48, kInf}},
  };
  std::string out;
  for (const Table& table : tables) {
    const auto bins = bin_edge_recall(steps, table.measure, table.edges);
    std::uint64_t all = 0;
    for (const EdgeRecallBin& bin : bins) all += bin.pixels;
    out += fmt::format("{:<28} {:>14} {:>8}\n", table.title, "share of gt px", "recall");
    for (const EdgeRecallBin& bin : bins) {
      if (bin.pixels == 0) continue;
      const std::string range =
          std::isinf(bin.hi) ? fmt::format("{:g} and more", bin.lo) : fmt::format("{:g} - {:g}", bin.lo, bin.hi);
      out += fmt::format("  {:<26} {:>14.3f} {:>8.3f}\n", range,
                         static_cast<double>(bin.pixels) / static_cast<double>(all),
                         static_cast<double>(bin.matched) / static_cast<double>(bin.pixels));
    }
  }
  return out;
}

std::string edge_recall_csv_header() {
  return "run,t_us,gt_id,length_px,normal_speed_px_s,parallel_gap_px,pixels,matched\n";
}

std::string edge_recall_csv_rows(const std::string& run, std::span<const EdgeStep> steps) {
  std::string out;
  const auto number = [](float v) {
    return std::isfinite(v) ? fmt::format("{:.3f}", v) : std::string(std::isnan(v) ? "" : "inf");
  };
  for (const EdgeStep& s : steps) {
    out += fmt::format("{},{},{},{:.3f},{},{},{},{}\n", run, s.t_us, s.id, s.length_px, number(s.normal_speed_px_s),
                       number(s.parallel_gap_px), s.pixels, s.matched);
  }
  return out;
}

void write_edge_recall_png(const std::filesystem::path& path, const EdgeRecall& recall, const std::string& title,
                           int scale) {
  const auto& picture = recall.picture();
  if (!picture)
    throw std::runtime_error("no step to draw for " + path.string() + ": the run ended before the picture's time");
  const SensorSize sensor = recall.sensor();
  constexpr int kBanner = 24;
  cv::Mat image(sensor.height * scale + kBanner, sensor.width * scale, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto width = static_cast<std::size_t>(sensor.width);
  for (const Segment& piece : picture->truth) {
    for_each_segment_sample(piece, sensor, [&](int x, int y) {
      const bool matched = picture->matched_map[static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x)] != 0;
      cv::rectangle(image, cv::Rect(x * scale, y * scale + kBanner, scale, scale),
                    matched ? cv::Scalar(60, 170, 60) : cv::Scalar(40, 40, 220), cv::FILLED);
    });
  }
  const auto at = [&](const Point2& p) {
    return cv::Point(static_cast<int>(std::lround(p.x() * static_cast<float>(scale))),
                     static_cast<int>(std::lround(p.y() * static_cast<float>(scale))) + kBanner);
  };
  for (const Segment& s : picture->predicted) {
    if (s.q0.allFinite() && s.q1.allFinite())
      cv::line(image, at(s.q0), at(s.q1), cv::Scalar(200, 90, 20), 1, cv::LINE_AA);
  }
  cv::putText(image,
              fmt::format("{} at {:.3f} s: true edges found (green) / missed (red), predicted (blue)", title,
                          static_cast<double>(picture->t_us) * 1e-6),
              cv::Point(4, 17), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  if (!media::write_image(path.string(), image)) throw std::runtime_error("could not write " + path.string());
}

}  // namespace evldt
