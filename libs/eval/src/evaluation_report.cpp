#include "evldt/eval/evaluation_report.hpp"

#include <limits>
#include <sstream>
#include <stdexcept>

namespace evldt {

EvaluationReport make_evaluation_report(const StreamEvaluator& evaluator) {
  EvaluationReport r;
  const EvaluationAccumulator& accuracy = evaluator.accuracy();
  r.tolerances.assign(accuracy.tolerance_fractions().begin(), accuracy.tolerance_fractions().end());
  for (std::size_t i = 0; i < r.tolerances.size(); ++i) r.accuracy.push_back(accuracy.summed_prf(i));
  r.steps = accuracy.steps();
  r.mean_predicted = accuracy.mean_predicted_segments();
  r.mean_ground_truth = accuracy.mean_ground_truth_segments();
  r.coverage = evaluator.coverage();
  r.hold_us = evaluator.hold_us();
  r.lifetime = evaluator.lifetimes().summary();
  r.tracking = evaluator.tracking().summary();
  if (const auto& visible = evaluator.visible_accuracy()) {
    if (evaluator.visibility_split() == nullptr) r.visible_min_normal_speed = evaluator.visible_min_normal_speed();
    for (std::size_t i = 0; i < r.tolerances.size(); ++i) r.visible.push_back(visible->summed_prf(i));
    const auto seen = static_cast<double>(evaluator.visible_truth_pixels());
    const auto unseen = static_cast<double>(evaluator.hidden_truth_pixels());
    r.visible_share = seen + unseen > 0 ? seen / (seen + unseen) : std::numeric_limits<double>::quiet_NaN();
  }
  r.per_second = evaluator.per_second();
  r.seconds_origin = evaluator.seconds_origin();
  return r;
}

namespace {
void write_accuracy(JsonWriter& json, const std::vector<double>& tolerances, const std::vector<Prf>& prfs) {
  json.key("accuracy").begin_array();
  for (std::size_t i = 0; i < prfs.size(); ++i) {
    json.begin_object().key("tolerance").value(tolerances[i]).key("precision").value(prfs[i].precision);
    json.key("recall").value(prfs[i].recall).key("f").value(prfs[i].f).end_object();
  }
  json.end_array();
}
}  // namespace

void write_evaluation_json(JsonWriter& json, const EvaluationReport& r) {
  json.key("steps").value(r.steps);
  json.key("coverage").begin_object().key("ground_truth_steps").value(r.coverage.ground_truth_steps);
  json.key("steps_without_prediction").value(r.coverage.steps_without_prediction);
  json.key("prediction_hold_us").value(static_cast<std::int64_t>(r.hold_us));
  json.key("predicted_steps").value(r.coverage.predicted_steps);
  json.key("predicted_steps_scored").value(r.coverage.predicted_steps_scored);
  json.key("predicted_steps_outside_ground_truth").value(r.coverage.predicted_steps_outside).end_object();
  write_accuracy(json, r.tolerances, r.accuracy);
  if (!r.visible.empty()) {
    json.key("visible_only").begin_object().key("min_normal_speed");
    if (r.visible_min_normal_speed) {
      json.value(static_cast<double>(*r.visible_min_normal_speed));
    } else {
      json.null();
    }
    json.key("visible_share").value(r.visible_share);
    write_accuracy(json, r.tolerances, r.visible);
    json.end_object();
  }
  json.key("cumulative_per_second").begin_array();
  for (const StreamEvaluator::Second& second : r.per_second) {
    const Prf& p = second.cumulative;
    json.begin_object().key("steps").value(second.steps);
    json.key("precision").value(p.precision).key("recall").value(p.recall).key("f").value(p.f).end_object();
  }
  json.end_array();
  json.key("mean_segments_per_step")
      .value(r.mean_predicted)
      .key("mean_gt_segments_per_step")
      .value(r.mean_ground_truth);
  json.key("lifetime").begin_object().key("ids").value(r.lifetime.count).key("mean_ms").value(r.lifetime.mean_ms);
  json.key("std_ms").value(r.lifetime.std_ms).key("max_ms").value(r.lifetime.max_ms).end_object();
  const TrackingSummary& t = r.tracking;
  json.key("tracking").begin_object().key("tolerance").value(r.tolerances.empty() ? 0.0 : r.tolerances.front());
  json.key("min_overlap").value(kDefaultMinOverlap).key("ground_truth_lines").value(t.ground_truth_lines);
  json.key("lines_never_matched").value(t.lines_never_matched).key("coverage").value(t.coverage);
  json.key("ids_per_line").value(t.ids_per_line).key("id_switches").value(t.id_switches);
  json.key("id_precision").value(t.id_precision).key("id_recall").value(t.id_recall).key("idf1").value(t.idf1);
  json.key("unassigned_matched_px").value(t.unassigned_matched_px);
  json.key("velocity_pairs").value(t.velocity_pairs).key("vel_err_med").value(t.velocity_error_median);
  json.key("vel_rel_med").value(t.velocity_relative_median);
  const IdSwitchCauses& c = t.switch_causes;
  json.key("id_switch_causes")
      .begin_object()
      .key("to_other_edge")
      .value(c.to_other_edge)
      .key("off_edge")
      .value(c.off_edge);
  json.key("returned").value(c.returned).key("redetected").value(c.redetected).key("taken_over").value(c.taken_over);
  json.key("after_gap").value(c.after_gap).end_object();
  json.end_object();
}

std::string evaluation_json(const EvaluationReport& report) {
  std::ostringstream out;
  JsonWriter json(out);
  json.begin_object();
  write_evaluation_json(json, report);
  json.end_object();
  if (!json.done()) throw std::logic_error("unbalanced JSON");
  return out.str();
}

}  // namespace evldt
