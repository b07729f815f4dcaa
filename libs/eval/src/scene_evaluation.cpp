#include "evldt/eval/scene_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "evldt/events/event_validator.hpp"
#include "evldt/lines/normal_motion.hpp"
#include "evldt/pipeline/realtime_engine.hpp"

namespace evldt {

GroundTruthSteps scene_ground_truth_steps(const Scene& scene, Timestamp step_us) {
  if (step_us <= 0) throw std::invalid_argument("ground-truth step must be positive");
  GroundTruthSteps steps;
  for (Timestamp t = 0; t <= scene.duration_us; t += step_us) steps.times.push_back(t);
  steps.segments_at = [scene = std::make_shared<const Scene>(scene), times = steps.times](
                          std::size_t index, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments.clear();
    ids.clear();
    for (const GtSegment& g : scene->visible_edges(times.at(index))) {
      segments.push_back({g.a.cast<float>(), g.b.cast<float>()});
      ids.push_back(static_cast<std::uint64_t>(g.gt_id));
    }
  };
  return steps;
}

GroundTruthSteps csv_ground_truth_steps(const std::vector<GroundTruthRow>& rows) {
  struct Step {
    std::vector<Segment> segments;
    std::vector<std::uint64_t> ids;
  };
  auto by_time = std::make_shared<std::map<Timestamp, Step>>();
  for (const GroundTruthRow& row : rows) {
    Step& step = (*by_time)[row.t_us];
    step.segments.push_back({row.segment.a.cast<float>(), row.segment.b.cast<float>()});
    step.ids.push_back(static_cast<std::uint64_t>(row.segment.gt_id));
  }
  GroundTruthSteps steps;
  for (const auto& entry : *by_time) steps.times.push_back(entry.first);
  steps.segments_at = [by_time, times = steps.times](std::size_t index, std::vector<Segment>& segments,
                                                     std::vector<std::uint64_t>& ids) {
    const Step& step = by_time->at(times.at(index));
    segments = step.segments;
    ids = step.ids;
  };
  return steps;
}

GroundTruthSteps steps_within(GroundTruthSteps truth, Timestamp first, Timestamp last) {
  GroundTruthSteps within;
  std::vector<std::size_t> kept;  // the index in `truth` of each step kept
  for (std::size_t i = 0; i < truth.times.size(); ++i) {
    if (truth.times[i] < first || truth.times[i] > last) continue;
    within.times.push_back(truth.times[i]);
    kept.push_back(i);
  }
  within.segments_at = [kept = std::move(kept), segments_at = std::move(truth.segments_at)](
                           std::size_t index, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments_at(kept.at(index), segments, ids);
  };
  return within;
}

Timestamp median_step_spacing(std::span<const Timestamp> sorted_times) {
  std::vector<Timestamp> gaps;
  for (std::size_t i = 1; i < sorted_times.size(); ++i) {
    if (sorted_times[i] > sorted_times[i - 1]) gaps.push_back(sorted_times[i] - sorted_times[i - 1]);
  }
  if (gaps.empty()) return 0;
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2), gaps.end());
  return gaps[gaps.size() / 2];
}

StreamEvaluator::StreamEvaluator(SensorSize sensor, std::vector<double> tolerance_fractions,
                                 GroundTruthSteps ground_truth, Timestamp hold_us)
    : accuracy_(tolerance_fractions),
      tracking_(sensor, tolerance_fractions.empty() ? 0.0 : diagonal_tolerance_px(sensor, tolerance_fractions.front())),
      ground_truth_(std::move(ground_truth)),
      hold_us_(hold_us),
      counts_(tolerance_fractions.size()) {
  if (hold_us_ < 0) throw std::invalid_argument("the hold of a prediction must not be negative");
  if (!std::is_sorted(ground_truth_.times.begin(), ground_truth_.times.end()) ||
      std::adjacent_find(ground_truth_.times.begin(), ground_truth_.times.end()) != ground_truth_.times.end()) {
    throw std::invalid_argument("ground-truth step times must increase");
  }
  for (const double fraction : tolerance_fractions) matchers_.emplace_back(sensor, fraction);
  coverage_.ground_truth_steps = ground_truth_.times.size();
}

void StreamEvaluator::keep_edge_recall(std::optional<Timestamp> picture_at_us) {
  edge_recall_.emplace(matchers_.front().sensor(), picture_at_us);
}

void StreamEvaluator::score_visible_only(VisibleOnly rule) {
  if (!rule.split && !(rule.min_normal_speed >= 0)) {
    throw std::invalid_argument("the least speed across itself of a visible edge must not be negative");
  }
  visible_rule_ = std::move(rule);
  std::vector<double> fractions(accuracy_.tolerance_fractions().begin(), accuracy_.tolerance_fractions().end());
  visible_accuracy_.emplace(fractions);
  visible_matcher_.emplace(matchers_.front().sensor());
  visible_counts_.resize(matchers_.size());
}

void StreamEvaluator::score_steps_before(Timestamp until) {
  const std::vector<Timestamp>& times = ground_truth_.times;
  for (; next_step_ < times.size() && times[next_step_] < until; ++next_step_) {
    const bool use_held = holding_ && times[next_step_] - held_t_ <= hold_us_;
    const std::span<const Segment> predicted = use_held ? std::span<const Segment>(held_) : std::span<const Segment>();
    const std::span<const std::uint64_t> predicted_ids =
        use_held ? std::span<const std::uint64_t>(held_ids_) : std::span<const std::uint64_t>();
    held_scored_ = held_scored_ || use_held;
    coverage_.steps_without_prediction += use_held ? 0 : 1;
    ground_truth_.segments_at(next_step_, truth_, truth_ids_);
    for (std::size_t i = 0; i < matchers_.size(); ++i) counts_[i] = matchers_[i].match(predicted, truth_);
    accuracy_.add_step(counts_, predicted.size(), truth_.size());
    const Timestamp t = times[next_step_];
    add_to_second(t, counts_[0]);
    const bool with_velocities = use_held && !held_velocities_.empty();
    if (with_velocities) normal_velocities_at(next_step_, 0.5f, truth_velocities_);
    tracking_.add_step(t, predicted_ids, predicted, truth_ids_, truth_,
                       with_velocities ? std::span<const float>(held_velocities_) : std::span<const float>(),
                       with_velocities ? std::span<const float>(truth_velocities_) : std::span<const float>());
    if (edge_recall_) {
      matchers_.front().matched_ground_truth(matched_map_);
      edge_recall_->add_step(t, truth_, truth_ids_, predicted, matched_map_);
    }
    if (visible_accuracy_) {
      if (visible_rule_.split) {
        visible_rule_.split(next_step_, truth_, visible_truth_, hidden_truth_);
      } else {
        normal_velocities_at(next_step_, 0.0f, speed_at_q0_);
        normal_velocities_at(next_step_, 1.0f, speed_at_q1_);
        split_by_normal_speed(truth_, speed_at_q0_, speed_at_q1_, visible_rule_.min_normal_speed, visible_truth_,
                              hidden_truth_);
      }
      visible_matcher_->match(predicted, visible_truth_, hidden_truth_, matchers_, visible_counts_);
      visible_accuracy_->add_step(visible_counts_, predicted.size(), visible_truth_.size());
      visible_pixels_ += visible_matcher_->visible_pixels();
      hidden_pixels_ += visible_matcher_->hidden_pixels();
    }
  }
}

void StreamEvaluator::normal_velocities_at(std::size_t index, float along, std::vector<float>& velocities) {
  // Where each line of this step crosses the normal through the point of its piece, at a
  // neighbouring step: the distance along that normal (NaN where the line is not seen).
  const std::size_t pieces = truth_.size();
  const auto crossings = [&](std::size_t step, std::vector<double>& distances) {
    distances.assign(pieces, std::numeric_limits<double>::quiet_NaN());
    ground_truth_.segments_at(step, neighbour_truth_, neighbour_ids_);
    for (std::size_t piece = 0; piece < pieces; ++piece) {
      const auto it = std::find(neighbour_ids_.begin(), neighbour_ids_.end(), truth_ids_[piece]);
      if (it == neighbour_ids_.end()) continue;
      const Segment& there = neighbour_truth_[static_cast<std::size_t>(it - neighbour_ids_.begin())];
      const Point2 n = unit_normal(truth_[piece]), m = unit_normal(there);
      const double facing = m.dot(n);
      if (std::abs(facing) < 0.5) continue;  // turned by more than 60 degrees in a step: no crossing to speak of
      const Point2 point = truth_[piece].q0 + along * (truth_[piece].q1 - truth_[piece].q0);
      distances[piece] = m.dot(there.q0 - point) / facing;
    }
  };
  const std::vector<Timestamp>& times = ground_truth_.times;
  const std::size_t before = index > 0 ? index - 1 : index, after = index + 1 < times.size() ? index + 1 : index;
  crossings(before, crossings_before_);
  crossings(after, crossings_after_);
  velocities.assign(pieces, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t piece = 0; piece < pieces; ++piece) {
    // A neighbour where the line is not seen gives way to this step itself (crossing at 0).
    double from = crossings_before_[piece], to = crossings_after_[piece];
    Timestamp t_from = times[before], t_to = times[after];
    if (!std::isfinite(from)) from = 0, t_from = times[index];
    if (!std::isfinite(to)) to = 0, t_to = times[index];
    if (t_to > t_from)
      velocities[piece] = static_cast<float>((to - from) / (static_cast<double>(t_to - t_from) * 1e-6));
  }
}

void StreamEvaluator::add_to_second(Timestamp t, const MatchCounts& counts) {
  // The seconds count from the whole second of the clock that holds the first step, so a clock that
  // starts at the Unix epoch's microseconds bins as one that starts at 0 (and nothing is allocated by
  // the clock's value).
  constexpr Timestamp kSecond = 1'000'000;
  if (!seconds_origin_) {
    const Timestamp into_second = ((t % kSecond) + kSecond) % kSecond;
    seconds_origin_ = t >= std::numeric_limits<Timestamp>::min() + into_second ? t - into_second : t;
  }
  // Steps come in time order, so t is at or after the origin: the difference is exact unsigned.
  const std::uint64_t since = static_cast<std::uint64_t>(t) - static_cast<std::uint64_t>(*seconds_origin_);
  const std::uint64_t second = since > 0 ? (since - 1) / kSecond : 0;
  if (second >= kMaxSeconds) {
    throw std::length_error("ground-truth steps span more than " + std::to_string(kMaxSeconds) +
                            " seconds: the per-second table would not fit (a step at " + std::to_string(t) + " us)");
  }
  if (per_second_.size() <= second) {
    per_second_.resize(static_cast<std::size_t>(second) + 1);
    steps_per_second_.resize(static_cast<std::size_t>(second) + 1);
  }
  per_second_[static_cast<std::size_t>(second)] += counts;
  ++steps_per_second_[static_cast<std::size_t>(second)];
}

std::vector<StreamEvaluator::Second> StreamEvaluator::per_second() const {
  std::vector<Second> seconds;
  MatchCounts sum;
  for (std::size_t k = 0; k < per_second_.size(); ++k) {
    sum += per_second_[k];
    seconds.push_back({steps_per_second_[k], prf(sum)});
  }
  return seconds;
}

void StreamEvaluator::add_prediction(Timestamp t, std::span<const std::uint64_t> ids,
                                     std::span<const Segment> predicted, std::span<const float> normal_velocities) {
  if (finished_) throw std::logic_error("prediction added after finish()");
  if (ids.size() != predicted.size()) throw std::invalid_argument("a predicted step needs one id per segment");
  if (!normal_velocities.empty() && normal_velocities.size() != predicted.size()) {
    throw std::invalid_argument("a predicted step needs one velocity per segment, or none");
  }
  if (holding_ && t < held_t_) throw std::invalid_argument("predicted steps must not go back in time");
  lifetimes_.observe_step(t, ids);
  if (!holding_ || t > held_t_) {
    score_steps_before(t);
    coverage_.predicted_steps_scored += held_scored_ ? 1 : 0;
    held_scored_ = false;
    ++coverage_.predicted_steps;
    const std::vector<Timestamp>& times = ground_truth_.times;
    if (times.empty() || t > times.back() || t < times.front() - hold_us_) ++coverage_.predicted_steps_outside;
  }
  holding_ = true;
  held_t_ = t;
  held_ids_.assign(ids.begin(), ids.end());
  held_.assign(predicted.begin(), predicted.end());
  held_velocities_.assign(normal_velocities.begin(), normal_velocities.end());
}

void StreamEvaluator::finish() {
  if (finished_) throw std::logic_error("finish() called twice");
  finished_ = true;
  score_steps_before(std::numeric_limits<Timestamp>::max());
  coverage_.predicted_steps_scored += held_scored_ ? 1 : 0;
}

Timestamp prediction_hold_us(std::span<const SegmentRow> rows, Timestamp output_period_us,
                             std::span<const Timestamp> truth_times) {
  std::vector<Timestamp> times;
  for (const SegmentRow& row : rows) times.push_back(row.t_us);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  Timestamp period = output_period_us > 0 ? output_period_us : median_step_spacing(times);
  if (period == 0) period = median_step_spacing(truth_times);  // fewer than two predicted steps
  return StreamEvaluator::hold_for_period(period);
}

StreamEvaluator evaluate_segment_rows(std::vector<SegmentRow> rows, GroundTruthSteps truth, SensorSize sensor,
                                      std::vector<double> tolerance_fractions, Timestamp output_period_us,
                                      std::optional<VisibleOnly> visible_only) {
  std::stable_sort(rows.begin(), rows.end(), [](const SegmentRow& a, const SegmentRow& b) { return a.t_us < b.t_us; });
  const Timestamp hold_us = prediction_hold_us(rows, output_period_us, truth.times);
  StreamEvaluator evaluator(sensor, std::move(tolerance_fractions), std::move(truth), hold_us);
  if (visible_only) evaluator.score_visible_only(std::move(*visible_only));
  std::vector<std::uint64_t> ids;
  std::vector<Segment> predicted;
  std::vector<float> velocities;
  for (std::size_t i = 0; i < rows.size();) {
    const Timestamp t = rows[i].t_us;
    ids.clear();
    predicted.clear();
    velocities.clear();
    bool any_velocity = false;
    for (; i < rows.size() && rows[i].t_us == t; ++i) {
      ids.push_back(rows[i].id);
      predicted.push_back(rows[i].segment);
      velocities.push_back(rows[i].normal_velocity);
      any_velocity = any_velocity || std::isfinite(rows[i].normal_velocity);
    }
    evaluator.add_prediction(t, ids, predicted,
                             any_velocity ? std::span<const float>(velocities) : std::span<const float>());
  }
  evaluator.finish();
  return evaluator;
}

StreamEvaluator evaluate_steps_against(const GroundTruthSteps& predicted, GroundTruthSteps truth, SensorSize sensor,
                                       std::vector<double> tolerance_fractions) {
  StreamEvaluator evaluator(sensor, std::move(tolerance_fractions), std::move(truth),
                            StreamEvaluator::hold_for_period(median_step_spacing(predicted.times)));
  std::vector<Segment> segments;
  std::vector<std::uint64_t> ids;
  for (std::size_t i = 0; i < predicted.times.size(); ++i) {
    predicted.segments_at(i, segments, ids);
    evaluator.add_prediction(predicted.times[i], ids, segments);
  }
  evaluator.finish();
  return evaluator;
}

StreamEvaluator make_scene_evaluator(const Scene& scene, std::vector<double> tolerance_fractions, Timestamp step_us) {
  return StreamEvaluator(scene.sensor, std::move(tolerance_fractions), scene_ground_truth_steps(scene, step_us),
                         StreamEvaluator::hold_for_period(step_us));
}

SceneRunResult evaluate_scene(const Scene& scene, const SimulatorConfig& sim, const PipelineConfig& config,
                              Timestamp step_us, StreamEvaluator& evaluator, StreamEvaluator* whole_lines, int thin) {
  EventSimulator simulator(scene, sim);
  EventValidator validator(scene.sensor, 0);
  DeterministicPipeline pipeline(config);
  std::vector<std::uint64_t> ids;
  std::vector<Segment> predicted, step_segments;
  std::vector<float> velocities;
  WholeLineSupport support;
  const auto add = [&](StreamEvaluator& to, Timestamp t, std::span<const TrackedLine> lines) {
    ids.clear();
    predicted.clear();
    velocities.clear();
    for (const TrackedLine& line : lines) {
      ids.push_back(line.id);
      predicted.push_back(line.segment);
      velocities.push_back(line.normal_velocity);
    }
    to.add_prediction(t, ids, predicted, velocities);
  };
  pipeline.set_output(
      step_us,
      [&](const OutputStep& step) {
        add(evaluator, step.t, step.segments.lines());
        if (whole_lines == nullptr) return;
        predicted.swap(step_segments);  // the segments' geometry, which add() made, for the support
        add(*whole_lines, step.t, step.whole_lines);
        support.add_step(predicted, step_segments);
      },
      /*whole_lines=*/whole_lines != nullptr);
  SceneRunResult result;
  EventBatch batch, thinned;
  while (true) {
    batch.clear();
    const bool more = simulator.run_until(simulator.now_us() + step_us, batch);
    result.events += batch.size();
    validator.filter(batch);
    if (thin > 1 && !batch.empty()) {
      // As the receiver decodes a thinned batch: every thin-th event, ending with the last.
      thinned.clear();
      for (std::size_t i = (batch.size() - 1) % static_cast<std::size_t>(thin); i < batch.size();
           i += static_cast<std::size_t>(thin)) {
        thinned.push_back(batch[i]);
      }
      pipeline.process(thinned, RealtimeEngine::stored_copies(thin));
    } else {
      pipeline.process(batch);
    }
    if (!more) break;
  }
  evaluator.finish();
  if (whole_lines != nullptr) whole_lines->finish();
  result.scene_seconds = static_cast<double>(scene.duration_us) * 1e-6;
  result.counters = pipeline.counters();
  result.whole_line_support = support.summary();
  return result;
}

}  // namespace evldt
