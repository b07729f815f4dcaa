#pragma once
// The fitting score f = r_o * r_e of a segment on a set of lattice entries (docs/design.md, section 4).

#include <cstdint>
#include <span>
#include <vector>

#include "evldt/lines/geometry.hpp"
#include "evldt/lines/point_set.hpp"

namespace evldt {

struct ScoreBreakdown {
  float occupancy = 0;            ///< r_o: share of 1-px bins along the segment hit by an inlier, at most 1
  float effective = 0;            ///< r_e: inliers / normaliser
  int inliers = 0;                ///< points of the event set within d_max of the segment, along its length
  float inlier_distance_sum = 0;  ///< sum of d1 over the inliers
  /// Sum over the inliers of their signed distance along the segment's normal (normal_motion.hpp):
  /// divided by the inliers, where the middle of the event band lies off the segment.
  float inlier_offset_sum = 0;
  [[nodiscard]] float score() const { return occupancy * effective; }
  [[nodiscard]] float mean_inlier_distance() const {
    return inliers ? inlier_distance_sum / static_cast<float>(inliers) : 0.0f;
  }
  /// Ranks tracking hypotheses: the higher score wins; on a tie (common: f is a ratio of small counts,
  /// flat while an edge stays within d_max) the segment closer to its inliers wins, so the line
  /// follows the middle of its event band instead of waiting until the edge has almost left it.
  [[nodiscard]] bool better_than(const ScoreBreakdown& other) const {
    const float f = score(), g = other.score();
    return f > g || (f == g && inliers > 0 && mean_inlier_distance() < other.mean_inlier_distance());
  }
};

class FittingScorer {
 public:
  /// max_length: the longest segment that will be scored (the sensor diagonal is always enough).
  FittingScorer(float inlier_distance, float max_length);

  /// Scores `segment` on the event set `points` (the ACTIVE entries; single-block tracking adds the
  /// inactive ones, so a line can follow an edge leaving its block). r_e = inliers / normaliser.
  ScoreBreakdown score(const Segment& segment, const PointSet& points, float normaliser);

 private:
  float inlier_distance_;
  std::vector<std::uint8_t> bins_;  // scratch: 1 where a 1-px bin holds an inlier (+ a spare bin), reused across calls
  std::vector<std::int32_t> point_bins_;  // scratch: each point's bin
  std::vector<float> point_offsets_;      // scratch: each point's signed distance if an inlier, else 0
};

}  // namespace evldt
