#pragma once
// The score of what an events-only camera can see. An edge gives events only while it moves across
// itself, so the true edges of a step are split where their speed across themselves crosses a
// threshold: the part at or above it is scored as usual, the part below it is left out, and so are
// the predicted pixels that no visible true pixel takes and that lie near such a part (they count
// neither for nor against a method).

#include <cstdint>
#include <span>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "evldt/eval/line_heatmap.hpp"

namespace evldt {

/// Splits each true piece where its line's speed across itself crosses `min_speed` (px/s): the speed
/// is taken as linear along the piece between speed_at_q0 and speed_at_q1 (signed, along one normal),
/// as a rigid motion of the image plane makes it. The parts moving at min_speed or more go to
/// `visible`, the rest to `hidden` (both cleared first); a piece of unknown speed (NaN) is visible.
void split_by_normal_speed(std::span<const Segment> truth, std::span<const float> speed_at_q0,
                           std::span<const float> speed_at_q1, float min_speed, std::vector<Segment>& visible,
                           std::vector<Segment>& hidden);

/// Heat-map counts of a prediction against the visible true edges, the hidden ones left out. Scratch
/// maps live in the object.
class VisibleOnlyMatcher {
 public:
  explicit VisibleOnlyMatcher(SensorSize sensor) : sensor_(sensor) {}

  /// counts[i]: matchers[i]'s counts of `predicted` against `visible` (its one-to-one matching),
  /// less the predicted pixels left unmatched that lie within matchers[i]'s tolerance of a hidden
  /// true pixel.
  void match(std::span<const Segment> predicted, std::span<const Segment> visible, std::span<const Segment> hidden,
             std::span<HeatmapMatcher> matchers, std::span<MatchCounts> counts);
  /// True pixels of the last match, visible and hidden (a pixel of both counts as visible).
  [[nodiscard]] std::uint64_t visible_pixels() const { return visible_pixels_; }
  [[nodiscard]] std::uint64_t hidden_pixels() const { return hidden_pixels_; }

 private:
  SensorSize sensor_;
  std::vector<std::uint8_t> predicted_map_, visible_map_, hidden_map_, matched_map_;
  cv::Mat to_hidden_;  ///< distance from each pixel to the nearest hidden true pixel
  std::uint64_t visible_pixels_ = 0, hidden_pixels_ = 0;
};

}  // namespace evldt
