#include "evldt/eval/tracking_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "evldt/eval/assignment.hpp"
#include "evldt/eval/line_heatmap.hpp"
#include "evldt/lines/normal_motion.hpp"

namespace evldt {

namespace {

constexpr std::size_t kNoSlot = std::numeric_limits<std::size_t>::max();

double squared_distance_to_segment(double px, double py, const Segment& s) {
  const double ax = s.q0.x(), ay = s.q0.y();
  const double dx = static_cast<double>(s.q1.x()) - ax, dy = static_cast<double>(s.q1.y()) - ay;
  const double length_squared = dx * dx + dy * dy;
  double t = length_squared > 0 ? ((px - ax) * dx + (py - ay) * dy) / length_squared : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = ax + t * dx - px, ey = ay + t * dy - py;
  return ex * ex + ey * ey;
}

bool finite(const Segment& s) { return s.q0.allFinite() && s.q1.allFinite(); }

double median_of(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(values.begin(), middle));
}

double ratio(double numerator, double denominator) {
  return denominator > 0 ? numerator / denominator : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

TrackingEvaluator::TrackingEvaluator(SensorSize sensor, double tolerance_px, double min_overlap)
    : sensor_(sensor), tolerance_px_(tolerance_px), min_overlap_(min_overlap) {
  if (!sensor.valid()) {
    throw std::invalid_argument("invalid sensor size " + std::to_string(sensor.width) + "x" +
                                std::to_string(sensor.height));
  }
  if (!std::isfinite(tolerance_px) || tolerance_px < 0) {
    throw std::invalid_argument("tracking tolerance must be finite and >= 0, got " + std::to_string(tolerance_px));
  }
  if (!(min_overlap > 0 && min_overlap <= 1)) {
    throw std::invalid_argument("minimum overlap must be in (0, 1], got " + std::to_string(min_overlap));
  }
}

std::size_t TrackingEvaluator::line_index(std::uint64_t gt_id) {
  const auto [it, inserted] = line_of_gt_id_.try_emplace(gt_id, lines_.size());
  if (inserted) {
    lines_.push_back({.gt_id = gt_id, .owners = {}});
    ids_of_line_.emplace_back();
    last_owner_.emplace_back();
    slot_of_line_.push_back(kNoSlot);
  }
  return it->second;
}

std::size_t TrackingEvaluator::predicted_index(std::uint64_t id) {
  return index_of_predicted_id_.try_emplace(id, index_of_predicted_id_.size()).first->second;
}

double TrackingEvaluator::measure_overlaps(const Segment& whole_segment, std::span<const Segment> truth) {
  std::fill(overlap_by_line_.begin(), overlap_by_line_.end(), 0.0);
  std::fill(hit_stamp_.begin(), hit_stamp_.end(), kNoSlot);
  // Clipped first, which also bounds the number of samples whatever a file says.
  const std::optional<Segment> on_sensor = clipped_to_sensor(whole_segment, sensor_);
  if (!on_sensor) return 0;
  const Segment& segment = *on_sensor;
  const double length = segment.length();
  if (!(length > 0)) return 0;
  const double tolerance_squared = tolerance_px_ * tolerance_px_;
  // Only pieces whose box, grown by the tolerance, meets the segment's box can be near it.
  const float min_x = std::min(segment.q0.x(), segment.q1.x()) - static_cast<float>(tolerance_px_);
  const float max_x = std::max(segment.q0.x(), segment.q1.x()) + static_cast<float>(tolerance_px_);
  const float min_y = std::min(segment.q0.y(), segment.q1.y()) - static_cast<float>(tolerance_px_);
  const float max_y = std::max(segment.q0.y(), segment.q1.y()) + static_cast<float>(tolerance_px_);
  candidates_.clear();
  for (std::size_t piece = 0; piece < truth.size(); ++piece) {
    const Segment& g = truth[piece];
    if (finite(g) && std::max(g.q0.x(), g.q1.x()) >= min_x && std::min(g.q0.x(), g.q1.x()) <= max_x &&
        std::max(g.q0.y(), g.q1.y()) >= min_y && std::min(g.q0.y(), g.q1.y()) <= max_y) {
      candidates_.push_back(piece);
    }
  }
  if (candidates_.empty()) return length;
  const auto samples = static_cast<std::size_t>(std::max(1.0, std::ceil(length / kOverlapSamplePx)));
  const double sample_length = length / static_cast<double>(samples);
  const double dx = static_cast<double>(segment.q1.x()) - segment.q0.x();
  const double dy = static_cast<double>(segment.q1.y()) - segment.q0.y();
  for (std::size_t k = 0; k < samples; ++k) {
    const double f = (static_cast<double>(k) + 0.5) / static_cast<double>(samples);
    const double px = segment.q0.x() + f * dx, py = segment.q0.y() + f * dy;
    for (const std::size_t piece : candidates_) {
      const std::size_t slot = slot_of_line_[line_of_piece_[piece]];
      // A sample near two pieces of one line counts once for it.
      if (hit_stamp_[slot] == k || squared_distance_to_segment(px, py, truth[piece]) > tolerance_squared) continue;
      hit_stamp_[slot] = k;
      overlap_by_line_[slot] += sample_length;
    }
  }
  return length;
}

void TrackingEvaluator::add_step(Timestamp t, std::span<const std::uint64_t> predicted_ids,
                                 std::span<const Segment> predicted, std::span<const std::uint64_t> truth_ids,
                                 std::span<const Segment> truth, std::span<const float> predicted_velocities,
                                 std::span<const float> truth_velocities) {
  if (predicted_ids.size() != predicted.size() || truth_ids.size() != truth.size()) {
    throw std::invalid_argument("tracking step: ids and segments differ in number");
  }
  if ((!predicted_velocities.empty() && predicted_velocities.size() != predicted.size()) ||
      (!truth_velocities.empty() && truth_velocities.size() != truth.size())) {
    throw std::invalid_argument("tracking step: velocities and segments differ in number");
  }
  const bool compare_velocities = !predicted_velocities.empty() && !truth_velocities.empty();
  if (stepped_ && t < last_t_) throw std::invalid_argument("tracking steps must come in time order");
  stepped_ = true;
  last_t_ = t;

  step_lines_.clear();
  line_of_piece_.resize(truth.size());
  for (std::size_t piece = 0; piece < truth.size(); ++piece) {
    const std::size_t line = line_index(truth_ids[piece]);
    line_of_piece_[piece] = line;
    if (slot_of_line_[line] == kNoSlot) {
      slot_of_line_[line] = step_lines_.size();
      step_lines_.push_back(line);
      first_piece_.resize(step_lines_.size());
      first_piece_.back() = piece;
    }
    if (const auto visible = clipped_to_sensor(truth[piece], sensor_)) ground_truth_px_ += visible->length();
  }
  overlap_by_line_.resize(step_lines_.size());
  hit_stamp_.resize(step_lines_.size());

  matches_.clear();
  const std::size_t step = steps_++;
  std::vector<std::pair<std::uint64_t, std::size_t>>& published = ids_at_step_.emplace_back();
  for (std::size_t i = 0; i < predicted.size(); ++i) {
    const auto [sighting, first] = sightings_.try_emplace(predicted_ids[i], IdSightings{step, step});
    sighting->second.last_step = step;
    published.emplace_back(predicted_ids[i], kNoSlot);
    const double length = measure_overlaps(predicted[i], truth);
    predicted_px_ += length;
    std::size_t best = kNoSlot;
    for (std::size_t slot = 0; slot < step_lines_.size(); ++slot) {
      if (overlap_by_line_[slot] <= 0) continue;
      if (best == kNoSlot || overlap_by_line_[slot] > overlap_by_line_[best] ||
          (overlap_by_line_[slot] == overlap_by_line_[best] &&
           lines_[step_lines_[slot]].gt_id < lines_[step_lines_[best]].gt_id)) {
        best = slot;
      }
    }
    if (best == kNoSlot || overlap_by_line_[best] < min_overlap_ * length) continue;
    const std::size_t line = step_lines_[best];
    published.back().second = line;
    if (compare_velocities) {
      const std::size_t piece = first_piece_[best];
      const double truth_velocity = truth_velocities[piece];
      if (std::isfinite(truth_velocity) && std::isfinite(predicted_velocities[i])) {
        // Along the true line's normal: a segment drawn the other way round has the opposite one.
        const double sign = unit_normal(predicted[i]).dot(unit_normal(truth[piece])) < 0 ? -1.0 : 1.0;
        const double error = std::abs(sign * predicted_velocities[i] - truth_velocity);
        velocity_errors_.push_back(error);
        if (std::abs(truth_velocity) >= kMinRelativeSpeed)
          relative_velocity_errors_.push_back(error / std::abs(truth_velocity));
      }
    }
    matches_.push_back({line, predicted_ids[i], overlap_by_line_[best]});
    pair_overlap_px_[(static_cast<std::uint64_t>(predicted_index(predicted_ids[i])) << 32) | line] +=
        overlap_by_line_[best];
  }

  std::sort(published.begin(), published.end());
  // Each line's matches together, the one covering most of it first (ties: the lower id).
  std::sort(matches_.begin(), matches_.end(), [](const Match& a, const Match& b) {
    if (a.line != b.line) return a.line < b.line;
    if (a.overlap_px != b.overlap_px) return a.overlap_px > b.overlap_px;
    return a.id < b.id;
  });
  for (const std::size_t line : step_lines_) {
    slot_of_line_[line] = kNoSlot;
    GroundTruthLineTrack& track = lines_[line];
    ++track.visible_steps;
    const auto group = std::equal_range(matches_.begin(), matches_.end(), Match{.line = line},
                                        [](const Match& a, const Match& b) { return a.line < b.line; });
    const LineOwnerStep& previous = last_owner_[line];
    if (group.first == group.second) {
      track.owners.push_back({t, false, 0});
      continue;
    }
    ++track.matched_steps;
    std::uint64_t representative = group.first->id;
    for (auto m = group.first; m != group.second; ++m) {
      ids_of_line_[line].insert(m->id);
      if (previous.matched && m->id == previous.id) representative = previous.id;
    }
    if (previous.matched && representative != previous.id) {
      ++track.id_switches;
      switches_.push_back(
          {line, step, previous.id, representative, !track.owners.empty() && !track.owners.back().matched});
    }
    track.distinct_ids = ids_of_line_[line].size();
    track.owners.push_back({t, true, representative});
    last_owner_[line] = track.owners.back();
  }
}

IdSwitchCauses TrackingEvaluator::classify_switches() const {
  IdSwitchCauses causes;
  for (const Switch& sw : switches_) {
    if (sw.after_gap) ++causes.after_gap;
    const auto& published = ids_at_step_[sw.step];
    const auto it = std::lower_bound(published.begin(), published.end(), std::pair(sw.old_id, std::size_t{0}));
    if (it != published.end() && it->first == sw.old_id) {
      // Published: it no longer matches this line, or the representative would have stayed.
      if (it->second != kNoSlot) {
        ++causes.to_other_edge;
      } else {
        ++causes.off_edge;
      }
      continue;
    }
    const IdSightings& old_seen = sightings_.at(sw.old_id);
    if (old_seen.last_step > sw.step) {
      ++causes.returned;
    } else if (sightings_.at(sw.new_id).first_step > old_seen.last_step) {
      ++causes.redetected;
    } else {
      ++causes.taken_over;
    }
  }
  return causes;
}

TrackingSummary TrackingEvaluator::summary() const {
  TrackingSummary s;
  s.ground_truth_lines = lines_.size();
  std::uint64_t visible = 0, matched = 0, lines_matched = 0, ids = 0;
  for (const GroundTruthLineTrack& line : lines_) {
    visible += line.visible_steps;
    matched += line.matched_steps;
    s.id_switches += line.id_switches;
    if (line.matched_steps == 0) {
      ++s.lines_never_matched;
    } else {
      ++lines_matched;
      ids += line.distinct_ids;
    }
  }
  s.coverage = ratio(static_cast<double>(matched), static_cast<double>(visible));
  s.ids_per_line = ratio(static_cast<double>(ids), static_cast<double>(lines_matched));

  // Sorted by key, so the assignment and the sums do not depend on the hash map's order.
  std::vector<std::pair<std::uint64_t, double>> overlaps(pair_overlap_px_.begin(), pair_overlap_px_.end());
  std::sort(overlaps.begin(), overlaps.end());
  std::vector<WeightedPair> pairs;
  pairs.reserve(overlaps.size());
  for (const auto& [key, overlap] : overlaps) {
    pairs.push_back({static_cast<std::uint32_t>(key >> 32), static_cast<std::uint32_t>(key & 0xffffffffu), overlap});
  }
  double matched_px = 0;
  for (const WeightedPair& pair : pairs) matched_px += pair.weight;
  for (const std::size_t chosen : max_weight_matching(index_of_predicted_id_.size(), lines_.size(), pairs)) {
    s.id_true_positive_px += pairs[chosen].weight;
  }
  s.unassigned_matched_px = matched_px - s.id_true_positive_px;
  s.velocity_pairs = velocity_errors_.size();
  s.velocity_error_median = median_of(velocity_errors_);
  s.velocity_relative_median = median_of(relative_velocity_errors_);
  s.switch_causes = classify_switches();
  s.predicted_px = predicted_px_;
  s.ground_truth_px = ground_truth_px_;
  s.id_precision = ratio(s.id_true_positive_px, predicted_px_);
  s.id_recall = ratio(s.id_true_positive_px, ground_truth_px_);
  s.idf1 = ratio(2 * s.id_true_positive_px, predicted_px_ + ground_truth_px_);
  return s;
}

}  // namespace evldt
