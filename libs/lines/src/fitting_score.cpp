#include "evldt/lines/fitting_score.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace evldt {

FittingScorer::FittingScorer(float inlier_distance, float max_length)
    : inlier_distance_(inlier_distance), bins_(static_cast<std::size_t>(std::ceil(max_length)) / 64 + 2, 0) {}

ScoreBreakdown FittingScorer::score(const Segment& segment, const PointSet& points, float normaliser) {
  ScoreBreakdown result;
  const Point2 along = segment.q1 - segment.q0;
  const float length = along.norm();
  if (!(length > 1e-3f) || normaliser <= 0) return result;
  const Point2 unit = along / length;
  const std::size_t bin_count = static_cast<std::size_t>(length) + 1;  // floor(d2) ranges over 0..floor(|L|)
  const std::size_t words = std::min(bins_.size(), (bin_count + 63) / 64);
  std::fill_n(bins_.begin(), words, 0);

  // Branch-free: about half the points are inliers, so a branch on it mispredicts. Sums and
  // counts are taken in point order, exactly as a branchy loop would (adding 0 changes nothing).
  const float q0x = segment.q0.x(), q0y = segment.q0.y(), ux = unit.x(), uy = unit.y();
  const float max_distance = inlier_distance_;
  const std::size_t last_bin = words * 64 - 1;
  const float* xs = points.x();
  const float* ys = points.y();
  std::uint64_t* bins = bins_.data();
  int inliers = 0;
  float distance_sum = 0;
  for (std::size_t i = 0, n = points.size(); i < n; ++i) {
    const float ox = xs[i] - q0x, oy = ys[i] - q0y;
    const float position = ox * ux + oy * uy;               // d2
    const float distance = std::abs(ox * uy - oy * ux);     // d1
    const bool inlier = (distance < max_distance) & (position >= 0.0f) & (position <= length);
    const std::size_t bin = std::min(static_cast<std::size_t>(inlier ? position : 0.0f), last_bin);
    bins[bin / 64] |= std::uint64_t{inlier} << (bin % 64);
    inliers += inlier;
    distance_sum += inlier ? distance : 0.0f;
  }
  int occupied = 0;
  for (std::size_t w = 0; w < words; ++w) occupied += std::popcount(bins[w]);
  result.inliers = inliers;
  result.inlier_distance_sum = distance_sum;
  result.occupancy = std::min(1.0f, static_cast<float>(occupied) / length);
  result.effective = static_cast<float>(result.inliers) / normaliser;
  return result;
}

}  // namespace evldt
