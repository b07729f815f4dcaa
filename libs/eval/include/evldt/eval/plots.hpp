#pragma once
// PNG charts of evaluation results, drawn with OpenCV so that no plotting dependency is needed.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "evldt/eval/tracking_metrics.hpp"

namespace evldt {

/// Size of every chart written here, in px.
inline constexpr int kPlotWidth = 720;
inline constexpr int kPlotHeight = 600;

/// One operating point of a detector, e.g. at one score threshold.
struct PrPoint {
  double threshold = 0;
  double precision = 0;
  double recall = 0;
  double f = 0;
};

/// Precision (y) against recall (x) on [0, 1] x [0, 1], with iso-F curves, each point labelled with
/// its threshold, joined in threshold order, and the point of best F named in the corner. Points
/// with a non-finite precision or recall are left out. Throws std::runtime_error naming the path if
/// the file cannot be written.
void write_pr_curve_png(const std::filesystem::path& path, std::span<const PrPoint> points, const std::string& title);

/// Bars of counts[k] over [k * bin_width_ms, (k + 1) * bin_width_ms), e.g. a lifetime histogram.
/// Throws std::invalid_argument unless bin_width_ms is finite and > 0, and std::runtime_error naming
/// the path if the file cannot be written.
void write_histogram_png(const std::filesystem::path& path, const std::vector<std::uint64_t>& counts,
                         double bin_width_ms, const std::string& title);

/// Most true lines that write_id_timeline_png draws, one row each.
inline constexpr std::size_t kTimelineMaxLines = 40;

/// Ids over time: one row per true line (the kTimelineMaxLines seen longest, in order of first
/// appearance), coloured at each step by the predicted id that stood for it (one colour per id, the
/// same in every row), grey where none matched, with a black tick at each id switch. A line that one
/// id follows for its whole life is one bar of one colour. Throws std::runtime_error naming the
/// path if the file cannot be written.
void write_id_timeline_png(const std::filesystem::path& path, std::span<const GroundTruthLineTrack> lines,
                           const std::string& title);

}  // namespace evldt
