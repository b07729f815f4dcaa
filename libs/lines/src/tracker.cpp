#include "evldt/lines/tracker.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

namespace evldt {

void blocks_along(const Segment& segment, const LatticeGeometry& geometry, std::vector<int>& cells) {
  const float b = static_cast<float>(geometry.block_size);
  const float half = static_cast<float>(geometry.block_size / 2);
  const Point2 along = segment.q1 - segment.q0;
  const float length = along.norm();
  if (!(length > 0.0f)) return;
  // Pull the ends inside by a hair so an endpoint on a border picks the block the segment enters.
  const Point2 inset = along * (1e-3f / length);
  const Point2 a = (segment.q0 + inset - Point2(half, half)) / b;  // lattice units
  const Point2 z = (segment.q1 - inset - Point2(half, half)) / b;
  int ci = static_cast<int>(std::floor(a.x())), cj = static_cast<int>(std::floor(a.y()));
  const int end_i = static_cast<int>(std::floor(z.x())), end_j = static_cast<int>(std::floor(z.y()));
  const Point2 d = z - a;
  const int step_i = d.x() > 0 ? 1 : -1, step_j = d.y() > 0 ? 1 : -1;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const float delta_x = d.x() != 0 ? 1.0f / std::abs(d.x()) : kInf;
  const float delta_y = d.y() != 0 ? 1.0f / std::abs(d.y()) : kInf;
  float next_x = d.x() != 0
                     ? (step_i > 0 ? (static_cast<float>(ci) + 1 - a.x()) : (a.x() - static_cast<float>(ci))) * delta_x
                     : kInf;
  float next_y = d.y() != 0
                     ? (step_j > 0 ? (static_cast<float>(cj) + 1 - a.y()) : (a.y() - static_cast<float>(cj))) * delta_y
                     : kInf;
  // Rounding can make the walk overshoot the end cell by one; the count bound stops it there.
  const int steps = std::abs(end_i - ci) + std::abs(end_j - cj);
  for (int s = 0; s <= steps; ++s) {
    if (ci >= 0 && cj >= 0 && ci < geometry.blocks_x && cj < geometry.blocks_y) cells.push_back(geometry.index(ci, cj));
    if (next_x < next_y) {
      ci += step_i;
      next_x += delta_x;
    } else {
      cj += step_j;
      next_y += delta_y;
    }
  }
}

EndpointMotion endpoint_motion(const Point2& endpoint, const Point2& segment_direction, const LatticeGeometry& geometry,
                               float perturbation_px) {
  const float b = static_cast<float>(geometry.block_size);
  const float half = static_cast<float>(geometry.block_size / 2);
  auto nearest_line = [&](float coordinate, int blocks) {
    const float k = std::clamp(std::round((coordinate - half) / b), 0.0f, static_cast<float>(blocks));
    return half + k * b;
  };
  const float line_x = nearest_line(endpoint.x(), geometry.blocks_x);  // nearest vertical lattice line
  const float line_y = nearest_line(endpoint.y(), geometry.blocks_y);  // nearest horizontal lattice line
  const float dx = std::abs(endpoint.x() - line_x), dy = std::abs(endpoint.y() - line_y);
  bool along_x;  // true: the endpoint slides along a horizontal border
  if (std::hypot(dx, dy) < 1.0f) {
    // Near a corner: follow the segment's normal, which is the direction the edge moves in.
    along_x = std::abs(segment_direction.y()) >= std::abs(segment_direction.x());
  } else {
    along_x = dy < dx;
  }
  if (along_x) return {Point2(endpoint.x(), line_y), Point2(perturbation_px, 0.0f)};
  return {Point2(line_x, endpoint.y()), Point2(0.0f, perturbation_px)};
}

namespace {
constexpr std::uint8_t kKept = 255;
static_assert(kReleaseReasonCount < kKept);
constexpr std::size_t kLinesPerClaim = 16;  // lines a worker claims at a time
}  // namespace

LineTracker::LineTracker(const LatticeGeometry& geometry, const ScoreParams& score, const TrackParams& track,
                         RoundWorkers* workers)
    : geometry_(geometry), score_params_(score), params_(track), round_workers_(workers) {
  const int threads = workers ? workers->threads() : 1;
  const float inlier_distance = score.inlier_distance_ratio * static_cast<float>(geometry.block_size);
  const float diagonal =
      std::hypot(static_cast<float>(geometry.sensor.width), static_cast<float>(geometry.sensor.height));
  const auto longest_walk = static_cast<std::size_t>(geometry.blocks_x + geometry.blocks_y + 2);
  workers_.reserve(static_cast<std::size_t>(threads));
  for (int w = 0; w < threads; ++w) {
    Worker& worker = workers_.emplace_back(Worker{FittingScorer(inlier_distance, diagonal), {}, {}, 0});
    worker.cells.reserve(longest_walk);
    worker.points.reserve(longest_walk * static_cast<std::size_t>(geometry.capacity));
  }
  outcome_.reserve(static_cast<std::size_t>(geometry.block_count()));  // at most one line per block
}

std::uint64_t LineTracker::settled_passes() const {
  std::uint64_t passes = 0;
  for (const Worker& worker : workers_) passes += worker.settled_passes;
  return passes;
}

void LineTracker::track(const ScarfLattice& lattice, LineMap& lines, Timestamp now) {
  const std::span<TrackedLine> all = lines.lines();
  const bool settled_ok = lattice.versions_of() == versions_of_;
  versions_of_ = lattice.versions_of();
  // Every line's pass reads the lattice and writes only the line, so workers share the list freely.
  const std::size_t n = all.size();
  outcome_.resize(n);
  std::atomic<std::size_t> next_line{0};  // the next line a worker claims
  auto track_claimed = [&](int w) {
    Worker& worker = workers_[static_cast<std::size_t>(w)];
    for (;;) {
      const std::size_t begin = next_line.fetch_add(kLinesPerClaim, std::memory_order_relaxed);
      if (begin >= n) return;
      for (std::size_t i = begin; i < std::min(n, begin + kLinesPerClaim); ++i) {
        ReleaseReason reason{};
        outcome_[i] =
            track_line(lattice, all[i], lines.settled_version(i), lines.band_centre(i), now, settled_ok, worker, reason)
                ? kKept
                : static_cast<std::uint8_t>(reason);
      }
    }
  };
  if (round_workers_ != nullptr && n >= kMinLinesToSplit) {
    round_workers_->run(track_claimed);
  } else {
    track_claimed(0);
  }
  // Release as one pass down the list does: the last line moves into a released line's slot.
  std::size_t i = 0;
  while (i < outcome_.size()) {
    if (outcome_[i] == kKept) {
      ++i;
      continue;
    }
    lines.release(i, static_cast<ReleaseReason>(outcome_[i]));
    outcome_[i] = outcome_.back();
    outcome_.pop_back();
  }
  lines.manage(kSuppressRatio);
  lines.observe_motion(now);
}

bool LineTracker::track_line(const ScarfLattice& lattice, TrackedLine& line, std::uint64_t& settled_version,
                             Point2& band_centre, Timestamp now, bool settled_ok, Worker& worker,
                             ReleaseReason& reason) const {
  const float b = static_cast<float>(geometry_.block_size);
  if (line.segment.length() < 0.5f * b) {
    reason = ReleaseReason::TooShort;
    return false;
  }
  std::vector<int>& cells = worker.cells;
  cells.clear();
  blocks_along(line.segment, geometry_, cells);
  if (cells.empty()) {
    reason = ReleaseReason::LeftSensor;
    return false;
  }
  std::uint64_t newest = 0;
  for (const int cell : cells) newest = std::max(newest, lattice.version(cell));
  if (settled_ok && settled_version != 0 && settled_version == newest) {
    ++worker.settled_passes;
    return judge(line, now, reason);
  }
  settled_version = 0;
  int active = 0;
  for (const int cell : cells) active += lattice.active_count(cell);
  if (active < geometry_.min_points()) {
    reason = ReleaseReason::TooFewPoints;
    return false;
  }

  // Event set: one block lends its inactive entries too, so a line can follow an edge leaving it.
  const bool single_block = cells.size() == 1;
  PointSet& points = worker.points;
  points.clear();
  for (const int cell : cells) points.add(lattice.entries(cell), /*include_inactive=*/single_block);
  float normaliser = static_cast<float>(geometry_.capacity);
  if (!single_block && params_.multi_block_norm == EffectiveRatioNorm::Union) {
    normaliser *= static_cast<float>(cells.size());
  }

  const Point2 direction = (line.segment.q1 - line.segment.q0).normalized();
  const EndpointMotion m0 = endpoint_motion(line.segment.q0, direction, geometry_, params_.perturbation_px);
  const EndpointMotion m1 = endpoint_motion(line.segment.q1, direction, geometry_, params_.perturbation_px);
  const Point2 sensor_max(static_cast<float>(geometry_.sensor.width), static_cast<float>(geometry_.sensor.height));
  auto inside = [&](const Point2& p) -> Point2 { return p.cwiseMax(Point2::Zero()).cwiseMin(sensor_max); };
  const std::array<Segment, 5> hypotheses{{
      {m0.base, m1.base},
      {inside(m0.base + m0.step), inside(m1.base + m1.step)},
      {inside(m0.base + m0.step), inside(m1.base - m1.step)},
      {inside(m0.base - m0.step), inside(m1.base + m1.step)},
      {inside(m0.base - m0.step), inside(m1.base - m1.step)},
  }};
  std::size_t best = 0;
  ScoreBreakdown best_score = worker.scorer.score(hypotheses[0], points, normaliser);
  for (std::size_t h = 1; h < hypotheses.size(); ++h) {
    const ScoreBreakdown s = worker.scorer.score(hypotheses[h], points, normaliser);
    if (s.better_than(best_score)) {  // strict: a full tie keeps the current segment
      best_score = s;
      best = h;
    }
  }
  // The base hypothesis is the segment itself once its ends sit on lattice lines (every pass puts
  // them there); a pass that keeps it has settled the line.
  if (best == 0 && hypotheses[0].q0 == line.segment.q0 && hypotheses[0].q1 == line.segment.q1) settled_version = newest;
  line.segment = hypotheses[best];
  line.score = best_score.score();
  band_centre = line.segment.centre();
  if (best_score.inliers > 0) {
    band_centre += unit_normal(line.segment) * (best_score.inlier_offset_sum / static_cast<float>(best_score.inliers));
  }
  return judge(line, now, reason);
}

bool LineTracker::judge(TrackedLine& line, Timestamp now, ReleaseReason& reason) const {
  if (line.score > score_params_.fit_threshold) {
    line.status = LineStatus::GoodTrack;
    line.last_good_us = now;
    return true;
  }
  line.status = LineStatus::BadTrack;
  if (now - line.last_good_us >= params_.bad_track_patience_us) {
    reason = ReleaseReason::BadTracks;
    return false;
  }
  return true;
}

}  // namespace evldt
