#pragma once
// Line heat-map accuracy as in the wireframe / BSDS line benchmarks: both segment sets are drawn as
// 1-px-wide line maps, and predicted pixels are matched one-to-one to ground-truth pixels within a
// tolerance that is a fraction of the image diagonal. Precision, recall and F follow from the counts.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/lines/geometry.hpp"

namespace evldt {

/// Largest sampling step along a segment when drawing it, in px.
inline constexpr double kRasterStepPx = 0.25;

/// The part of a segment on the sensor [0, W] x [0, H], or nothing (also for a non-finite end).
[[nodiscard]] std::optional<Segment> clipped_to_sensor(const Segment& segment, SensorSize sensor);

/// Calls visit(x, y) for the pixel of each sample of the segment that rasterise draws, in order
/// from q0 (a pixel comes once per sample in it, so mostly several times).
void for_each_segment_sample(const Segment& segment, SensorSize sensor, const std::function<void(int x, int y)>& visit);

/// Draws the segments into a W*H row-major map (resized and cleared here): a pixel is 1 where some
/// sample of a segment, taken at most kRasterStepPx apart and including both ends, falls in it.
/// Samples off the sensor are dropped, so partly visible segments are clipped; segments with a
/// non-finite end are skipped.
void rasterise(std::span<const Segment> segments, SensorSize sensor, std::vector<std::uint8_t>& map);

/// Pixel counts of one comparison: "matched" pairs one predicted pixel with one ground-truth pixel.
struct MatchCounts {
  std::uint64_t predicted = 0;
  std::uint64_t ground_truth = 0;
  std::uint64_t matched = 0;

  MatchCounts& operator+=(const MatchCounts& other) {
    predicted += other.predicted;
    ground_truth += other.ground_truth;
    matched += other.matched;
    return *this;
  }
  friend bool operator==(const MatchCounts&, const MatchCounts&) = default;
};

struct Prf {
  double precision = 0;
  double recall = 0;
  double f = 0;
};

/// precision = matched / predicted, recall = matched / ground_truth, F = 2PR / (P + R), which is
/// 2 matched / (predicted + ground_truth). What has an empty denominator is undefined, NaN (reported
/// as "n/a" and JSON null): precision of no predicted pixel, recall of no ground-truth pixel, F when
/// both are empty. So an empty prediction of a non-empty scene scores n/a / 0 / 0, predictions on
/// an empty scene 0 / n/a / 0: nothing predicted is never a perfect score.
[[nodiscard]] Prf prf(const MatchCounts& counts);

/// The matching radius in px: fraction of the image diagonal hypot(W, H).
[[nodiscard]] double diagonal_tolerance_px(SensorSize sensor, double tolerance_fraction);

/// Matches predicted to ground-truth line pixels one-to-one, maximising the number of pairs whose
/// distance (of pixel centres) is <= diagonal_tolerance_px: Hopcroft-Karp on the pixel graph. The
/// BSDS benchmark solves a min-cost assignment with a high outlier cost instead; that gives the same
/// count unless giving up one pair shortens the others by two outlier costs in all, which takes some
/// 200 pairs (tests/eval/reference_matching.hpp). Scratch buffers live in the object and are
/// reused: a warmed-up matcher allocates only when a call needs more room than any call before it.
/// The result is deterministic (pixels and neighbours are visited in a fixed order).
class HeatmapMatcher {
 public:
  /// Throws std::invalid_argument for an invalid sensor or a negative / non-finite fraction.
  HeatmapMatcher(SensorSize sensor, double tolerance_fraction);

  [[nodiscard]] MatchCounts match(std::span<const Segment> predicted, std::span<const Segment> ground_truth);
  /// The same on line maps already drawn (W*H row-major, non-zero = line pixel), e.g. by rasterise;
  /// throws std::invalid_argument if a map has the wrong size.
  [[nodiscard]] MatchCounts match_maps(std::span<const std::uint8_t> predicted_map,
                                       std::span<const std::uint8_t> ground_truth_map);

  /// The ground-truth pixels the last match paired with a predicted one, as a W*H row-major map
  /// (resized here): 1 where matched.
  void matched_ground_truth(std::vector<std::uint8_t>& map) const;
  /// The pixels of `predicted_map` (the one the last match_maps was given) that it paired with a
  /// ground-truth pixel, as a W*H row-major map (resized here): 1 where matched.
  void matched_predicted(std::span<const std::uint8_t> predicted_map, std::vector<std::uint8_t>& map) const;

  [[nodiscard]] SensorSize sensor() const { return sensor_; }
  [[nodiscard]] double tolerance_px() const { return tolerance_px_; }

 private:
  struct Pixel {
    int x = 0;
    int y = 0;
    std::uint32_t cell = 0;
  };
  [[nodiscard]] std::uint32_t cell_of(int x, int y) const {
    return static_cast<std::uint32_t>((y / cell_size_) * cell_columns_ + x / cell_size_);
  }
  void bucket_ground_truth(std::span<const std::uint8_t> ground_truth_map);
  void build_graph_and_match_greedily(std::span<const std::uint8_t> predicted_map);
  bool layer_from_free_predictions();
  void augment_from(std::uint32_t root);

  SensorSize sensor_;
  double tolerance_px_ = 0;
  std::int64_t max_distance_squared_ = 0;  ///< in px^2

  std::vector<std::uint8_t> predicted_map_;
  std::vector<std::uint8_t> ground_truth_map_;

  // Ground-truth pixels bucketed into square cells no smaller than the radius, so every neighbour
  // of a pixel lies in the 3x3 cells around it. Cell c holds bucketed_[cell_start_[c] .. cell_start_[c + 1]).
  int cell_size_ = 1;
  int cell_columns_ = 0;
  int cell_rows_ = 0;
  std::vector<Pixel> ground_truth_;  ///< row-major order
  std::vector<std::uint32_t> cell_start_;
  std::vector<Pixel> bucketed_;  ///< row-major within each cell

  // Bipartite graph: predicted pixel u's ground-truth neighbours (positions in bucketed_) are
  // neighbours_[first_neighbour_[u] .. first_neighbour_[u + 1]).
  std::vector<std::uint32_t> first_neighbour_;
  std::vector<std::uint32_t> neighbours_;

  // Hopcroft-Karp state.
  std::vector<std::uint32_t> mate_of_predicted_;
  std::vector<std::uint32_t> mate_of_ground_truth_;
  std::vector<std::uint32_t> layer_;
  std::vector<std::uint32_t> next_edge_;
  std::vector<std::uint32_t> queue_;
  std::vector<std::uint32_t> path_;
  std::uint32_t free_layer_ = 0;  ///< layer at which the current phase reaches free ground-truth pixels
  std::uint64_t matched_ = 0;
};

}  // namespace evldt
