#pragma once
// Recall per ground-truth edge: which true edges a method misses, against what makes an
// edge hard to see - its image speed across itself (an event camera sees an edge only as it moves
// across itself), its length, and how close the nearest parallel edge lies (two edges in one block).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/lines/geometry.hpp"

namespace evldt {

/// One visible piece of a true edge at one ground-truth step.
struct EdgeStep {
  Timestamp t_us = 0;
  std::uint64_t id = 0;
  float length_px = 0;
  /// How fast the edge's line moved across itself since the previous step, px/s (NaN at its first step).
  float normal_speed_px_s = 0;
  /// Distance to the nearest other true edge within kParallelDegrees that overlaps it along its
  /// length, px (infinite when there is none).
  float parallel_gap_px = 0;
  std::uint32_t pixels = 0;   ///< its pixels in the ground-truth line map
  std::uint32_t matched = 0;  ///< of them, matched to a predicted pixel
};

class EdgeRecall {
 public:
  static constexpr float kParallelDegrees = 10;

  /// picture_at_us: the step at or after this time is kept for a picture (write_edge_recall_png).
  explicit EdgeRecall(SensorSize sensor, std::optional<Timestamp> picture_at_us = std::nullopt)
      : sensor_(sensor), picture_at_us_(picture_at_us) {}
  /// One scored step: the true pieces and their line ids, the prediction scored against them, and
  /// the ground-truth pixels the matcher paired (HeatmapMatcher::matched_ground_truth). A pixel two
  /// pieces share counts for both.
  void add_step(Timestamp t, std::span<const Segment> truth, std::span<const std::uint64_t> ids,
                std::span<const Segment> predicted, std::span<const std::uint8_t> matched_map);
  [[nodiscard]] const std::vector<EdgeStep>& steps() const { return steps_; }

  /// The step kept for a picture.
  struct Picture {
    Timestamp t_us = 0;
    std::vector<Segment> truth, predicted;
    std::vector<std::uint8_t> matched_map;
  };
  [[nodiscard]] const std::optional<Picture>& picture() const { return picture_; }
  [[nodiscard]] SensorSize sensor() const { return sensor_; }

 private:
  SensorSize sensor_;
  std::optional<Timestamp> picture_at_us_;
  std::optional<Picture> picture_;
  std::vector<EdgeStep> steps_;
  struct Seen {
    Timestamp t_us;
    Segment first_piece;
  };
  std::unordered_map<std::uint64_t, Seen> previous_;  // per line id: its first piece at its last step
  std::vector<std::uint32_t> pixels_;                 // scratch: one piece's distinct pixels
};

/// Ground-truth pixels and the matched share of them, of the steps whose value lies in [lo, hi).
struct EdgeRecallBin {
  double lo = 0, hi = 0;
  std::uint64_t pixels = 0, matched = 0;
};
/// The steps binned by one of their values at the given bin edges (NaN values go in no bin).
enum class EdgeMeasure { NormalSpeed, Length, ParallelGap };
std::vector<EdgeRecallBin> bin_edge_recall(std::span<const EdgeStep> steps, EdgeMeasure measure,
                                           std::span<const double> edges);
/// The three tables (speed, length, parallel gap) as text, with each bin's share of all pixels.
std::string edge_recall_tables(std::span<const EdgeStep> steps);
/// One row per EdgeStep: run,t_us,gt_id,length_px,normal_speed_px_s,parallel_gap_px,pixels,matched.
std::string edge_recall_csv_header();
std::string edge_recall_csv_rows(const std::string& run, std::span<const EdgeStep> steps);
/// The kept step drawn `scale` times the sensor's size: true edges' pixels green where matched and
/// red where missed, the predicted segments in blue over them. Throws std::runtime_error when there
/// is no picture or it cannot be written.
void write_edge_recall_png(const std::filesystem::path& path, const EdgeRecall& recall, const std::string& title,
                           int scale = 3);

}  // namespace evldt
