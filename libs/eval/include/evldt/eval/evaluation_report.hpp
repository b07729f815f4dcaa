#pragma once
// The figures of one scored prediction stream, made once from a StreamEvaluator, and their JSON:
// evldt-eval prints and writes them (each run of --json), Python's evaluate() returns the same
// object, and the demo reads evldt-eval's. One set of figures under one set of keys.

#include <optional>
#include <string>
#include <vector>

#include "evldt/eval/scene_evaluation.hpp"
#include "evldt/json/json_writer.hpp"

namespace evldt {

struct EvaluationReport {
  std::vector<double> tolerances;  ///< fractions of the diagonal
  std::vector<Prf> accuracy;       ///< summed over the steps, per tolerance
  std::uint64_t steps = 0;
  double mean_predicted = 0, mean_ground_truth = 0;  ///< segments per step
  StepCoverage coverage;
  Timestamp hold_us = 0;
  LifetimeSummary lifetime;
  TrackingSummary tracking;  ///< at the first tolerance
  /// score_visible_only: against the true edges an events-only camera can see, per tolerance (empty
  /// when not scored), by their speed across themselves (none: by the events along them).
  std::vector<Prf> visible;
  std::optional<float> visible_min_normal_speed;
  double visible_share = 0;                         ///< of the true pixels, those seen (NaN without any)
  std::vector<StreamEvaluator::Second> per_second;  ///< cumulative, at the first tolerance
  std::optional<Timestamp> seconds_origin;          ///< t0 of per_second
};

/// The report of a finished evaluator.
EvaluationReport make_evaluation_report(const StreamEvaluator& evaluator);

/// Writes the report's keys into the JSON object open in `json`: steps, coverage, accuracy,
/// visible_only (when scored), cumulative_per_second, mean_segments_per_step,
/// mean_gt_segments_per_step, lifetime and tracking (docs/tools.md). A ratio without a denominator
/// is null.
void write_evaluation_json(JsonWriter& json, const EvaluationReport& report);

/// The report as one JSON object.
std::string evaluation_json(const EvaluationReport& report);

}  // namespace evldt
