#pragma once
// Scoring a stream of predicted segments against ground truth over the ground truth's time range:
// every ground-truth step is scored (heat-map counts at each tolerance, and the tracking metrics at the
// first tolerance), whatever the prediction covers, and the lifetime of every predicted id is followed.

#include <cmath>
#include <functional>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "evldt/eval/accumulator.hpp"
#include "evldt/eval/edge_recall.hpp"
#include "evldt/eval/line_heatmap.hpp"
#include "evldt/eval/tracking_metrics.hpp"
#include "evldt/eval/visible_score.hpp"
#include "evldt/eval/whole_line_support.hpp"
#include "evldt/pipeline/deterministic_pipeline.hpp"
#include "evldt/pipeline/segment_csv.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/ground_truth_csv.hpp"

namespace evldt {

/// The times at which ground truth is known, and its segments at each.
struct GroundTruthSteps {
  std::vector<Timestamp> times;  ///< strictly increasing
  /// Fills `segments` with the visible line pieces of step `index` (an index into `times`) and `ids`
  /// with the id of the true line of each (pieces of one line share its id).
  std::function<void(std::size_t index, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids)> segments_at;
};

/// A scene's exact visible edges at t = 0, step_us, 2 step_us, ... up to its duration (the steps
/// evldt-sim writes with --gt-period-us = step_us).
GroundTruthSteps scene_ground_truth_steps(const Scene& scene, Timestamp step_us);
/// The steps of a ground-truth CSV: each distinct time of its rows. (A step with no visible edge
/// has no row, so it cannot be a step here.)
GroundTruthSteps csv_ground_truth_steps(const std::vector<GroundTruthRow>& rows);
/// The steps of `truth` at times in [first, last], each with its own segments (segments_at's
/// indices are the kept steps').
GroundTruthSteps steps_within(GroundTruthSteps truth, Timestamp first, Timestamp last);

/// Splits the true pieces of step `index` into what an events-only camera can see and what it
/// cannot (visible_score.hpp).
using VisibilitySplit = std::function<void(std::size_t index, std::span<const Segment> truth,
                                           std::vector<Segment>& visible, std::vector<Segment>& hidden)>;

/// Scoring also against what an events-only camera can see: by the true edges' speed across
/// themselves (simulated ground truth), or by a split of its own (LSD's lines with event support).
struct VisibleOnly {
  float min_normal_speed = 2.0f;  ///< px/s
  VisibilitySplit split;          ///< used instead of the speed where set
  [[nodiscard]] static VisibleOnly by_speed(float min_normal_speed) { return {min_normal_speed, {}}; }
  [[nodiscard]] static VisibleOnly by_split(VisibilitySplit split) { return {0.0f, std::move(split)}; }
};

/// How a prediction stream lined up with the ground-truth steps.
struct StepCoverage {
  std::uint64_t ground_truth_steps = 0;
  std::uint64_t steps_without_prediction = 0;  ///< scored against an empty prediction
  std::uint64_t predicted_steps = 0;           ///< distinct times of the prediction
  std::uint64_t predicted_steps_scored = 0;    ///< used by at least one ground-truth step
  std::uint64_t predicted_steps_outside = 0;   ///< after the last ground-truth step or before the first one's reach
};

/// The rule: ground-truth step t is scored against the latest predicted step p <= t when t - p <=
/// hold_us, and against an empty prediction otherwise (all of its ground truth counts as missed).
/// hold_us is one output period with half a period of slack for jitter (kHoldPeriods), so a method
/// that outputs nothing for a while, or a live system that stalls, loses that time's recall, while
/// a prediction that lags by up to one period is scored as it stands. Predicted steps later than the
/// last ground-truth step, or earlier than the first by more than hold_us, are counted, not scored.
/// Every predicted step counts towards the lifetimes of its ids.
class StreamEvaluator {
 public:
  static constexpr double kHoldPeriods = 1.5;
  /// The hold for predictions output every `period_us`: kHoldPeriods of it.
  [[nodiscard]] static Timestamp hold_for_period(Timestamp period_us) {
    return std::llround(kHoldPeriods * static_cast<double>(period_us));
  }
  StreamEvaluator(SensorSize sensor, std::vector<double> tolerance_fractions, GroundTruthSteps ground_truth,
                  Timestamp hold_us);
  /// One predicted step; times must not decrease (throws std::invalid_argument), and a step at the
  /// time of the previous one replaces it. normal_velocities (px/s, one per segment, or empty when
  /// not known) are scored against the true lines' (TrackingSummary::velocity_error_median).
  void add_prediction(Timestamp t, std::span<const std::uint64_t> ids, std::span<const Segment> predicted,
                      std::span<const float> normal_velocities = {});
  /// Scores the ground-truth steps after the last prediction; call once, after the last add_prediction.
  void finish();

  [[nodiscard]] const EvaluationAccumulator& accuracy() const { return accuracy_; }
  [[nodiscard]] const LifetimeTracker& lifetimes() const { return lifetimes_; }
  /// Tracking metrics, at the first tolerance.
  [[nodiscard]] const TrackingEvaluator& tracking() const { return tracking_; }
  [[nodiscard]] const StepCoverage& coverage() const { return coverage_; }
  /// One second of the paper's view: its ground-truth steps, and the P/R/F of the counts summed over
  /// the steps up to its end (at the first tolerance).
  struct Second {
    std::uint64_t steps = 0;
    Prf cumulative;
  };
  /// The paper's view: element k - 1 holds the steps in (t0 + k - 1 s, t0 + k s], for each second up to
  /// the last step's. Seconds count from the whole second of the clock that holds the first step, t0
  /// (seconds_origin()), which the first second also holds. Throws std::length_error past kMaxSeconds.
  [[nodiscard]] std::vector<Second> per_second() const;
  /// t0 of per_second(); none before the first step.
  [[nodiscard]] std::optional<Timestamp> seconds_origin() const { return seconds_origin_; }
  static constexpr std::uint64_t kMaxSeconds = 1'000'000;  ///< of the per-second table: 11.6 days
  [[nodiscard]] Timestamp hold_us() const { return hold_us_; }
  /// Also keep the recall of each true edge at each step, at the first tolerance (before any step).
  /// picture_at_us: also keep the step at or after that time for a picture.
  void keep_edge_recall(std::optional<Timestamp> picture_at_us = std::nullopt);
  /// The recall per edge, when kept.
  [[nodiscard]] const std::optional<EdgeRecall>& edge_recall() const { return edge_recall_; }
  /// Also score against only what an events-only camera can see (visible_score.hpp), before any
  /// step: by the rule's split, or else the true edges where they move across themselves at
  /// min_normal_speed px/s or more, the speed from the lines' places at the neighbouring steps
  /// (throws std::invalid_argument if negative).
  void score_visible_only(VisibleOnly rule);
  /// That score, when asked for.
  [[nodiscard]] const std::optional<EvaluationAccumulator>& visible_accuracy() const { return visible_accuracy_; }
  /// The split it was given (VisibleOnly::split), or nullptr.
  [[nodiscard]] const VisibilitySplit* visibility_split() const {
    return visible_accuracy_ && visible_rule_.split ? &visible_rule_.split : nullptr;
  }
  /// The speed the visible score asks of a true edge, where it is by speed (px/s).
  [[nodiscard]] float visible_min_normal_speed() const { return visible_rule_.min_normal_speed; }
  /// Of the true pixels over all steps, those moving fast enough to be seen and those not (with
  /// score_visible_only).
  [[nodiscard]] std::uint64_t visible_truth_pixels() const { return visible_pixels_; }
  [[nodiscard]] std::uint64_t hidden_truth_pixels() const { return hidden_pixels_; }
  [[nodiscard]] const GroundTruthSteps& ground_truth() const { return ground_truth_; }

 private:
  /// Scores every ground-truth step before `until` against the held prediction.
  void score_steps_before(Timestamp until);
  /// The true lines' velocities across themselves at step `index`, one per piece of truth_ (NaN
  /// where the line is seen at neither neighbouring step), at the point `along` (0: q0, 1: q1) of
  /// each piece: central differences of where each line lies along the piece's normal through it.
  void normal_velocities_at(std::size_t index, float along, std::vector<float>& velocities);
  /// Adds a step's counts at the first tolerance to its second.
  void add_to_second(Timestamp t, const MatchCounts& counts);

  std::vector<HeatmapMatcher> matchers_;
  EvaluationAccumulator accuracy_;
  std::optional<EvaluationAccumulator> visible_accuracy_;
  std::optional<VisibleOnlyMatcher> visible_matcher_;
  VisibleOnly visible_rule_;
  std::vector<float> speed_at_q0_, speed_at_q1_;
  std::vector<Segment> visible_truth_, hidden_truth_;
  std::vector<MatchCounts> visible_counts_;
  std::uint64_t visible_pixels_ = 0, hidden_pixels_ = 0;
  LifetimeTracker lifetimes_;
  TrackingEvaluator tracking_;
  std::vector<MatchCounts> per_second_;  // first tolerance, by second of the step time
  std::vector<std::uint64_t> steps_per_second_;
  std::optional<Timestamp> seconds_origin_;  // t0 of cumulative_per_second(), set by the first step
  GroundTruthSteps ground_truth_;
  Timestamp hold_us_;
  std::size_t next_step_ = 0;
  bool holding_ = false;
  bool held_scored_ = false;
  Timestamp held_t_ = 0;
  std::vector<std::uint64_t> held_ids_;
  std::vector<Segment> held_;
  std::vector<float> held_velocities_;
  std::vector<float> truth_velocities_;
  std::vector<Segment> neighbour_truth_;
  std::vector<std::uint64_t> neighbour_ids_;
  std::vector<double> crossings_before_, crossings_after_;
  std::vector<std::uint64_t> truth_ids_;
  std::vector<Segment> truth_;
  std::vector<MatchCounts> counts_;
  StepCoverage coverage_;
  bool finished_ = false;
  std::optional<EdgeRecall> edge_recall_;
  std::vector<std::uint8_t> matched_map_;  // scratch of the edge recall
};

/// How long a predicted step of `rows` (any order) holds when scored: StreamEvaluator::kHoldPeriods of
/// `output_period_us`, else of the median spacing of their steps, else (fewer than two steps) of the
/// ground truth's.
Timestamp prediction_hold_us(std::span<const SegmentRow> rows, Timestamp output_period_us,
                             std::span<const Timestamp> truth_times);
/// Scores predicted segment rows (of a CSV, a log or Python; any order, sorted by time here) on
/// ground-truth steps with StreamEvaluator's rule and a hold of kHoldPeriods output periods.
/// output_period_us 0: the median spacing of the predicted steps (of the ground truth's, with fewer
/// than two). With `visible_only`, also scores what an events-only camera can see
/// (StreamEvaluator::score_visible_only).
StreamEvaluator evaluate_segment_rows(std::vector<SegmentRow> rows, GroundTruthSteps truth, SensorSize sensor,
                                      std::vector<double> tolerance_fractions, Timestamp output_period_us,
                                      std::optional<VisibleOnly> visible_only = std::nullopt);

/// The nominal output period of a prediction: the median spacing of its distinct step times, or 0
/// with fewer than two.
Timestamp median_step_spacing(std::span<const Timestamp> sorted_times);

struct SceneRunResult {
  std::uint64_t events = 0;
  double scene_seconds = 0;
  PipelineCounters counters;
  SupportSummary whole_line_support;  ///< of the whole lines by the segments of their step, when scored
};

/// Simulates the scene, runs the deterministic pipeline on it with an output every step_us and scores
/// it on the scene's ground-truth steps (scene_ground_truth_steps) with a hold of
/// kHoldPeriods * step_us. `evaluator` must have been made for those steps; so must `whole_lines`,
/// which, when given, scores the whole lines (WholeLineStage, config.whole_lines) of each output
/// and measures their support by the segments (WholeLineSupport's defaults). `thin` > 1 models a
/// service past its means: every batch is thinned to every thin-th event, ending with its last, and
/// stored as evldt-lines stores a batch it thinned (RealtimeEngine::stored_copies).
SceneRunResult evaluate_scene(const Scene& scene, const SimulatorConfig& sim, const PipelineConfig& config,
                              Timestamp step_us, StreamEvaluator& evaluator, StreamEvaluator* whole_lines = nullptr,
                              int thin = 1);

/// One ground truth's steps scored as the prediction against another's (LSD on frames against the
/// exact lines: how good the imitation is), each predicted step held for kHoldPeriods of their
/// median spacing.
StreamEvaluator evaluate_steps_against(const GroundTruthSteps& predicted, GroundTruthSteps truth, SensorSize sensor,
                                       std::vector<double> tolerance_fractions);

/// The evaluator evaluate_scene expects for a scene.
StreamEvaluator make_scene_evaluator(const Scene& scene, std::vector<double> tolerance_fractions, Timestamp step_us);

}  // namespace evldt
