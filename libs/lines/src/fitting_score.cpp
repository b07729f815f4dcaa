#include "evldt/lines/fitting_score.hpp"

#include <algorithm>
#include <cmath>

namespace evldt {

FittingScorer::FittingScorer(float inlier_distance, float max_length)
    : inlier_distance_(inlier_distance), bins_(static_cast<std::size_t>(std::ceil(max_length)) + 2, 0) {}

ScoreBreakdown FittingScorer::score(const Segment& segment, const PointSet& points, float normaliser) {
  ScoreBreakdown result;
  const Point2 along = segment.q1 - segment.q0;
  const float length = along.norm();
  if (!(length > 1e-3f) || normaliser <= 0) return result;
  const Point2 unit = along / length;
  // A bin per pixel of length, one byte each, and a spare one past them for the points that are no
  // inliers (a bitset's read-modify-write of one word per point made each point wait for the
  // previous one's store: half of the scoring time).
  const std::size_t bin_count =
      std::min(static_cast<std::size_t>(length) + 1, bins_.size() - 1);  // floor(d2) ranges over 0..floor(|L|)
  std::fill_n(bins_.begin(), bin_count + 1, std::uint8_t{0});

  // Two passes. The first is branch-free arithmetic the compiler vectorises: each point's bin, or
  // the spare bin when it is no inlier, and its signed distance along the normal, or 0. The second
  // marks the bins and sums the distances and offsets in point order, exactly as a loop over the
  // inliers would (adding 0 changes nothing).
  const std::size_t n = points.size();
  if (point_bins_.size() < n) {  // grows to the largest event set once, then stays
    point_bins_.resize(n);
    point_offsets_.resize(n);
  }
  const float q0x = segment.q0.x(), q0y = segment.q0.y(), ux = unit.x(), uy = unit.y();
  const float max_distance = inlier_distance_;
  const auto last_bin = static_cast<std::int32_t>(bin_count - 1);
  const std::int32_t spare_bin = last_bin + 1;
  const float* xs = points.x();
  const float* ys = points.y();
  std::int32_t* point_bins = point_bins_.data();
  float* point_offsets = point_offsets_.data();
  std::int32_t inliers = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float ox = xs[i] - q0x, oy = ys[i] - q0y;
    const float position = ox * ux + oy * uy;  // d2
    const float offset = oy * ux - ox * uy;    // along the normal (-uy, ux); d1 is its size
    const bool inlier = (std::abs(offset) < max_distance) & (position >= 0.0f) & (position <= length);
    point_bins[i] = inlier ? std::min(static_cast<std::int32_t>(position), last_bin) : spare_bin;
    point_offsets[i] = inlier ? offset : 0.0f;
    inliers += inlier;
  }
  std::uint8_t* bins = bins_.data();
  float distance_sum = 0, offset_sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bins[point_bins[i]] = 1;
    distance_sum += std::abs(point_offsets[i]);
    offset_sum += point_offsets[i];
  }
  int occupied = 0;
  for (std::size_t b = 0; b < bin_count; ++b) occupied += bins[b];
  result.inliers = inliers;
  result.inlier_distance_sum = distance_sum;
  result.inlier_offset_sum = offset_sum;
  result.occupancy = std::min(1.0f, static_cast<float>(occupied) / length);
  result.effective = static_cast<float>(result.inliers) / normaliser;
  return result;
}

}  // namespace evldt
