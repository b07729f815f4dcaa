#include "evldt/lines/fitting_score.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace evldt {

FittingScorer::FittingScorer(float inlier_distance, float max_length)
    : inlier_distance_(inlier_distance), bins_(static_cast<std::size_t>(std::ceil(max_length)) / 64 + 2, 0) {}

ScoreBreakdown FittingScorer::score(const Segment& segment, std::span<const LatticeEntry> entries, bool use_inactive,
                                    float normaliser) {
  ScoreBreakdown result;
  const Point2 along = segment.q1 - segment.q0;
  const float length = along.norm();
  if (!(length > 1e-3f) || normaliser <= 0) return result;
  const Point2 unit = along / length;
  const std::size_t bin_count = static_cast<std::size_t>(length) + 1;  // floor(d2) ranges over 0..floor(|L|)
  const std::size_t words = std::min(bins_.size(), (bin_count + 63) / 64);
  std::fill_n(bins_.begin(), words, 0);

  for (const LatticeEntry& e : entries) {
    if (!use_inactive && !e.active()) continue;
    const Point2 offset = Point2(e.cx(), e.cy()) - segment.q0;
    const float position = offset.dot(unit);                // d2
    const float distance = std::abs(cross2(offset, unit));  // d1
    if (!(distance < inlier_distance_ && position >= 0.0f && position <= length)) continue;
    const auto bin = std::min(static_cast<std::size_t>(position), words * 64 - 1);
    bins_[bin / 64] |= std::uint64_t{1} << (bin % 64);
    ++result.inliers;
    result.inlier_distance_sum += distance;
  }
  int occupied = 0;
  for (std::size_t w = 0; w < words; ++w) occupied += std::popcount(bins_[w]);
  result.occupancy = std::min(1.0f, static_cast<float>(occupied) / length);
  result.effective = static_cast<float>(result.inliers) / normaliser;
  return result;
}

}  // namespace evldt
