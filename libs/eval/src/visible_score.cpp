#include "evldt/eval/visible_score.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace evldt {

void split_by_normal_speed(std::span<const Segment> truth, std::span<const float> speed_at_q0,
                           std::span<const float> speed_at_q1, float min_speed, std::vector<Segment>& visible,
                           std::vector<Segment>& hidden) {
  if (speed_at_q0.size() != truth.size() || speed_at_q1.size() != truth.size()) {
    throw std::invalid_argument("split_by_normal_speed needs a speed at each end of each piece");
  }
  visible.clear();
  hidden.clear();
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Segment& piece = truth[i];
    const float v0 = speed_at_q0[i], v1 = speed_at_q1[i];
    if (!std::isfinite(v0) || !std::isfinite(v1)) {
      visible.push_back(piece);
      continue;
    }
    const auto at = [&](float s) -> Point2 { return piece.q0 + s * (piece.q1 - piece.q0); };
    // |v(s)| < min_speed, v linear in s, holds on one interval [low, high] of the line.
    float low = 0, high = 0;
    if (v1 == v0) {
      const bool slow = std::abs(v0) < min_speed;
      low = slow ? 0.0f : 1.0f;
      high = slow ? 1.0f : 0.0f;
    } else {
      const float a = (-min_speed - v0) / (v1 - v0), b = (min_speed - v0) / (v1 - v0);
      low = std::clamp(std::min(a, b), 0.0f, 1.0f);
      high = std::clamp(std::max(a, b), 0.0f, 1.0f);
    }
    if (high <= low) {
      visible.push_back(piece);
      continue;
    }
    if (low > 0) visible.push_back({piece.q0, at(low)});
    hidden.push_back({at(low), at(high)});
    if (high < 1) visible.push_back({at(high), piece.q1});
  }
}

void VisibleOnlyMatcher::match(std::span<const Segment> predicted, std::span<const Segment> visible,
                               std::span<const Segment> hidden, std::span<HeatmapMatcher> matchers,
                               std::span<MatchCounts> counts) {
  if (counts.size() != matchers.size()) throw std::invalid_argument("one count per matcher");
  rasterise(predicted, sensor_, predicted_map_);
  rasterise(visible, sensor_, visible_map_);
  rasterise(hidden, sensor_, hidden_map_);
  visible_pixels_ = hidden_pixels_ = 0;
  for (std::size_t p = 0; p < visible_map_.size(); ++p) {
    visible_pixels_ += visible_map_[p] != 0;
    hidden_pixels_ += hidden_map_[p] != 0 && visible_map_[p] == 0;
  }
  if (hidden_pixels_ > 0) {
    // Distances between pixel centres to the nearest hidden true pixel (exact Euclidean).
    cv::Mat background(sensor_.height, sensor_.width, CV_8U);
    for (std::size_t p = 0; p < hidden_map_.size(); ++p)
      background.data[p] = hidden_map_[p] != 0 && visible_map_[p] == 0 ? 0 : 255;
    cv::distanceTransform(background, to_hidden_, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  }
  for (std::size_t i = 0; i < matchers.size(); ++i) {
    // The visible true pixels take what predicted pixels they can first; of the rest, those that lie
    // near a hidden true pixel are left out (they may well be on that edge), the others are wrong.
    counts[i] = matchers[i].match_maps(predicted_map_, visible_map_);
    if (hidden_pixels_ == 0) continue;
    matchers[i].matched_predicted(predicted_map_, matched_map_);
    // A small slack over the tolerance: the transform's distances are floats of integer offsets.
    const float tolerance = static_cast<float>(matchers[i].tolerance_px()) + 1e-3f;
    const auto* near_hidden = to_hidden_.ptr<float>();
    std::uint64_t left_out = 0;
    for (std::size_t p = 0; p < predicted_map_.size(); ++p) {
      left_out += predicted_map_[p] != 0 && matched_map_[p] == 0 && near_hidden[p] <= tolerance;
    }
    counts[i].predicted -= left_out;
  }
}

}  // namespace evldt
