// evldt-eval: line heat-map precision / recall / F and lifetimes of predicted segments against
// ground truth, from files or by running the pipeline on a built-in scene (also over thresholds).

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <memory>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/app/simulator_options.hpp"
#include "evldt/eval/evaluation_report.hpp"
#include "evldt/eval/frame_ground_truth.hpp"
#include "evldt/eval/overlay.hpp"
#include "evldt/eval/plots.hpp"
#include "evldt/eval/scene_evaluation.hpp"
#include "evldt/eval/whole_line_support.hpp"
#include "evldt/frames/frame_reader.hpp"
#include "evldt/json/json_writer.hpp"
#include "evldt/pipeline/segment_csv.hpp"
#include "evldt/sim/ground_truth_csv.hpp"
#include "evldt/sources/event_source.hpp"
#include "evldt/transport/lcm_log.hpp"

namespace {

using namespace evldt;

struct Options {
  std::filesystem::path segments, whole_lines, ground_truth, frames_gt, write_gt, json, pr_png, lifetime_png,
      tracks_png, overlay, edge_recall, edge_recall_png;
  LsdParams lsd;
  std::string lcm_channel;
  std::string label;         ///< of the --segments row
  std::string frames_topic;  ///< of a bag or HDF5 file given to --frames-gt
  std::vector<double> tolerances{0.01, 0.02};
  std::vector<float> pr_thresholds;
  Timestamp step_us = 10000;
  int thin = 1;  ///< scene runs: every batch thinned to every thin-th event, stored as evldt-lines would
  Timestamp output_period_us = 0;  ///< of a segment file; 0: its median step spacing
  double histogram_bin_ms = 50;
  bool per_second = false;
  bool visible_only = false;
  float min_normal_speed = 2.0f;  ///< px/s: slower true edges give no events (--visible-only)
  std::filesystem::path events;   ///< --visible-only with --frames-gt: the events that go with the frames
  EventSupportRule support;
};

// The events of --frames-gt's recording: --events, else the frames' own file (AEDAT 4.0, a bag, an
// HDF5 file hold both), or the events.txt of an Event Camera Dataset folder.
std::filesystem::path events_of_frames(const Options& options) {
  if (!options.events.empty()) return options.events;
  if (std::filesystem::is_directory(options.frames_gt)) return options.frames_gt / "events.txt";
  return options.frames_gt;
}

// --visible-only: the rule for the ground truth of these options. Simulated edges are seen by their
// speed; LSD's lines of frames by the recording's events along them (read once, here).
std::optional<VisibleOnly> visible_rule(const Options& options, const GroundTruthSteps& truth, SensorSize sensor) {
  if (!options.visible_only) return std::nullopt;
  if (options.frames_gt.empty()) return VisibleOnly::by_speed(options.min_normal_speed);
  const std::filesystem::path path = events_of_frames(options);
  const auto source = open_recording(path, std::nullopt, "", std::numeric_limits<Timestamp>::max() / 4);
  auto supported = std::make_shared<std::vector<std::vector<std::uint8_t>>>(
      event_supported_pieces(truth, sensor, options.support, [&](EventBatch& batch) { return source->read(batch); }));
  std::size_t lines = 0, seen = 0;
  for (const auto& step : *supported) {
    lines += step.size();
    seen += static_cast<std::size_t>(std::count(step.begin(), step.end(), std::uint8_t{1}));
  }
  spdlog::info("{} of {} LSD lines have events of {} along them (half or more of their pixels within +-{:.1f} ms)",
               seen, lines, path.string(), static_cast<double>(options.support.half_window_us) * 1e-3);
  return VisibleOnly::by_split([supported](std::size_t index, std::span<const Segment> pieces,
                                           std::vector<Segment>& visible, std::vector<Segment>& hidden) {
    visible.clear();
    hidden.clear();
    const std::vector<std::uint8_t>& flags = (*supported)[index];
    for (std::size_t k = 0; k < pieces.size(); ++k)
      (k < flags.size() && flags[k] ? visible : hidden).push_back(pieces[k]);
  });
}

struct Report {
  std::string label;
  std::optional<float> threshold;  ///< set for pipeline runs; a segment file's is unknown
  bool whole_lines = false;        ///< the whole lines of a pipeline run
  EvaluationReport figures;
  std::optional<SupportSummary> support;  ///< whole lines: their support by the segments of their step
  std::vector<EdgeStep> edge_steps;       ///< with --edge-recall: each true edge at each step
  std::uint64_t events = 0;
  double scene_seconds = 0, wall_seconds = 0;
};

Report make_report(const StreamEvaluator& evaluator) {
  Report r;
  r.figures = make_evaluation_report(evaluator);
  if (evaluator.edge_recall()) r.edge_steps = evaluator.edge_recall()->steps();
  return r;
}

// The event time an lcm-log's event batches span, if it has any: a recording of the live system is
// scored over the time it recorded, so a stall inside it costs recall.
std::optional<std::pair<Timestamp, Timestamp>> recorded_event_span(const std::filesystem::path& log,
                                                                   const std::string& lines_channel) {
  const std::string events_channel =
      lines_channel.starts_with("LINES_") ? "EVENTS_" + lines_channel.substr(std::string_view("LINES_").size()) : "";
  try {
    LcmLogEventReader reader(log, events_channel, std::numeric_limits<Timestamp>::max() / 4);
    std::optional<std::pair<Timestamp, Timestamp>> span;
    EventBatch batch;
    while (reader.read(batch)) {
      for (const Timestamp t : batch.t) {
        span = span ? std::pair(std::min(span->first, t), std::max(span->second, t)) : std::pair(t, t);
      }
    }
    return span;
  } catch (const std::runtime_error&) {
    return std::nullopt;  // no event batches recorded: the ground truth's own range
  }
}

// --write-gt: the steps as a ground-truth CSV, so that other methods are scored on the same lines.
void write_ground_truth(const GroundTruthSteps& truth, const std::filesystem::path& path) {
  GroundTruthCsvWriter out(path);
  std::vector<Segment> segments;
  std::vector<std::uint64_t> ids;
  std::vector<GtSegment> rows;
  for (std::size_t i = 0; i < truth.times.size(); ++i) {
    truth.segments_at(i, segments, ids);
    rows.clear();
    for (std::size_t k = 0; k < segments.size(); ++k) {
      rows.push_back({static_cast<int>(ids[k]), segments[k].q0.cast<double>(), segments[k].q1.cast<double>()});
    }
    out.write_step(truth.times[i], rows);
  }
  out.close();
  spdlog::info("wrote the ground truth ({} steps) to {}", truth.times.size(), path.string());
}

// The ground truth: LSD on the frames of --frames-gt (as the paper), else the scene's or the CSV's
// exact lines.
GroundTruthSteps ground_truth_steps(const Options& options, const SimulatorOptions& sim, SensorSize sensor) {
  GroundTruthSteps truth;
  if (!options.frames_gt.empty()) {
    const auto frames = open_frames(options.frames_gt, options.frames_topic, sensor);
    truth = frame_ground_truth_steps(*frames, options.lsd);
    spdlog::info("ground truth: LSD on {} frames of {} (segments of {} px or more)", truth.times.size(),
                 options.frames_gt.string(), options.lsd.min_length_px);
  } else {
    truth = sim.scene_selected() ? scene_ground_truth_steps(sim.scene(), options.step_us)
                                 : csv_ground_truth_steps(read_ground_truth_csv(options.ground_truth));
  }
  if (!options.write_gt.empty()) write_ground_truth(truth, options.write_gt);
  return truth;
}

// The rule is StreamEvaluator's: every ground-truth step, against the latest predicted step at or
// before it within 1.5 output periods.
StreamEvaluator evaluate_files(const Options& options, std::vector<SegmentRow> rows, SensorSize sensor,
                               const SimulatorOptions& sim) {
  const bool from_log = is_lcm_log(options.segments);
  GroundTruthSteps truth = ground_truth_steps(options, sim, sensor);
  if (from_log) {
    if (const auto span = recorded_event_span(options.segments, options.lcm_channel)) {
      const std::size_t before = truth.times.size();
      truth = steps_within(std::move(truth), span->first, span->second);
      spdlog::info("scoring the {} of {} ground-truth steps within the recorded events ({:.3f} .. {:.3f} s)",
                   truth.times.size(), before, static_cast<double>(span->first) * 1e-6,
                   static_cast<double>(span->second) * 1e-6);
    }
  }
  std::optional<VisibleOnly> visible = visible_rule(options, truth, sensor);
  return evaluate_segment_rows(std::move(rows), std::move(truth), sensor, options.tolerances, options.output_period_us,
                               std::move(visible));
}

// An undefined ratio (nothing predicted, or no ground truth) is "n/a", never a perfect or zero score.
std::string figure(double value, int decimals = 3) {
  return std::isfinite(value) ? fmt::format("{:.{}f}", value, decimals) : "n/a";
}

void print_table(const std::vector<Report>& reports, const Options& options) {
  std::printf("%-24s %6s", "run", "f_th");
  for (const double tol : options.tolerances) {
    const std::string at = fmt::format("@{:g}%", tol * 100);  // 1%, 0.2%
    std::printf("  %6s  %6s  %6s", ("P" + at).c_str(), ("R" + at).c_str(), ("F" + at).c_str());
  }
  std::printf(
      "  segs/step  gt/step  gt_steps  no_pred  ids  life_mean_ms life_max_ms  cover  ids/gt  id_sw   IDF1"
      "  vel_err_med  vel_rel_med\n");
  for (const Report& r : reports) {
    if (r.threshold) {
      std::printf("%-24s %6.3f", r.label.c_str(), static_cast<double>(*r.threshold));
    } else {
      std::printf("%-24s %6s", r.label.c_str(), "-");
    }
    const EvaluationReport& e = r.figures;
    for (const Prf& p : e.accuracy)
      std::printf("  %6s  %6s  %6s", figure(p.precision).c_str(), figure(p.recall).c_str(), figure(p.f).c_str());
    std::printf("  %9.1f  %7.1f  %8llu  %7llu  %4llu  %11.1f %11.1f  %5s  %6s  %5llu  %5s  %11s  %11s\n",
                e.mean_predicted, e.mean_ground_truth, static_cast<unsigned long long>(e.coverage.ground_truth_steps),
                static_cast<unsigned long long>(e.coverage.steps_without_prediction),
                static_cast<unsigned long long>(e.lifetime.count), e.lifetime.mean_ms, e.lifetime.max_ms,
                figure(e.tracking.coverage).c_str(), figure(e.tracking.ids_per_line, 1).c_str(),
                static_cast<unsigned long long>(e.tracking.id_switches), figure(e.tracking.idf1).c_str(),
                figure(e.tracking.velocity_error_median, 1).c_str(),
                figure(e.tracking.velocity_relative_median).c_str());
  }
}

// --visible-only: the runs again, scored against the true edges an events-only camera can see.
void print_visible(const std::vector<Report>& reports, const Options& options) {
  std::printf(
      "scored against what an events-only camera can see: the true edges moving across themselves at %g px/s or more\n",
      static_cast<double>(options.min_normal_speed));
  std::printf("%-32s %8s", "run", "visible");
  for (const double tol : options.tolerances) {
    const std::string at = fmt::format("@{:g}%", tol * 100);
    std::printf("  %6s  %6s  %6s", ("P" + at).c_str(), ("R" + at).c_str(), ("F" + at).c_str());
  }
  std::printf("\n");
  for (const Report& r : reports) {
    if (r.figures.visible.empty()) continue;
    std::printf("%-32s %8s", (r.label + " visible").c_str(), figure(r.figures.visible_share).c_str());
    for (const Prf& p : r.figures.visible)
      std::printf("  %6s  %6s  %6s", figure(p.precision).c_str(), figure(p.recall).c_str(), figure(p.f).c_str());
    std::printf("\n");
  }
}

// Why ids changed, and what identity cost in length: a line per run that had switches.
void print_switch_causes(const std::vector<Report>& reports) {
  for (const Report& r : reports) {
    const TrackingSummary& t = r.figures.tracking;
    if (t.id_switches == 0) continue;
    const IdSwitchCauses& c = t.switch_causes;
    std::printf(
        "id switches of %s: %llu to another edge, %llu off the edge, %llu returned later, %llu detected again, "
        "%llu taken over (%llu after a gap); %.0f px matched under another id than the line's, IDF1 with one id per "
        "line %s\n",
        r.label.c_str(), static_cast<unsigned long long>(c.to_other_edge), static_cast<unsigned long long>(c.off_edge),
        static_cast<unsigned long long>(c.returned), static_cast<unsigned long long>(c.redetected),
        static_cast<unsigned long long>(c.taken_over), static_cast<unsigned long long>(c.after_gap),
        t.unassigned_matched_px,
        figure(2 * (t.id_true_positive_px + t.unassigned_matched_px) / (t.predicted_px + t.ground_truth_px)).c_str());
  }
}

void print_support(const std::string& label, const SupportSummary& s) {
  std::printf(
      "whole-line support of %s: %s of %.0f px within 2 px of a segment of the same step; %llu of %llu lines "
      "(%s) under 60%% supported\n",
      label.c_str(), figure(s.supported_share).c_str(), s.length_px, static_cast<unsigned long long>(s.weak_lines),
      static_cast<unsigned long long>(s.lines), figure(s.weak_share).c_str());
}

void write_support_json(JsonWriter& json, const SupportSummary& s) {
  json.key("whole_line_support").begin_object().key("steps").value(s.steps).key("lines").value(s.lines);
  json.key("length_px").value(s.length_px).key("supported_share").value(s.supported_share);
  json.key("weak_lines").value(s.weak_lines).key("weak_share").value(s.weak_share).end_object();
}

// Steps of a segment file: its rows grouped by time, in whatever order the rows come.
std::map<Timestamp, std::vector<Segment>> steps_of(const std::vector<SegmentRow>& rows) {
  std::map<Timestamp, std::vector<Segment>> steps;
  for (const SegmentRow& row : rows) steps[row.t_us].push_back(row.segment);
  return steps;
}

// --overlay: the frames with LSD's lines and the lines held at each, as scored.
void write_overlay_pictures(const Options& options, const StreamEvaluator& scored,
                            const std::vector<SegmentRow>& segments, const std::vector<SegmentRow>& whole_lines,
                            SensorSize sensor) {
  const Timestamp whole_line_hold =
      prediction_hold_us(whole_lines, options.output_period_us, scored.ground_truth().times);
  const auto frames = open_frames(options.frames_gt, options.frames_topic, sensor);
  const std::size_t pictures =
      write_overlays(options.overlay, *frames, scored.ground_truth(), {segments, scored.hold_us()},
                     {whole_lines, whole_line_hold}, scored.visibility_split());
  spdlog::info("wrote {} pictures of the scored frames to {}", pictures, options.overlay.string());
}

// The predicted segments of --segments: a CSV, or the segment lists of an lcm-log.
std::vector<SegmentRow> read_segments(const Options& options) {
  return is_lcm_log(options.segments) ? read_segment_log(options.segments, options.lcm_channel)
                                      : read_segment_csv(options.segments);
}

// The support of a whole-line file by the segments of the same run (evldt-offline -o and
// --whole-lines): every step of the whole lines against the segments of the same time.
SupportSummary file_support(const std::vector<SegmentRow>& segment_rows,
                            const std::vector<SegmentRow>& whole_line_rows) {
  const auto whole = steps_of(whole_line_rows);
  const auto segments = steps_of(segment_rows);
  WholeLineSupport support;
  std::uint64_t unmatched = 0;
  static const std::vector<Segment> kNone;
  for (const auto& [t, lines] : whole) {
    const auto found = segments.find(t);
    if (found == segments.end()) ++unmatched;
    support.add_step(lines, found == segments.end() ? kNone : found->second);
  }
  if (unmatched > 0)
    spdlog::warn("{} whole-line steps have no segment step of the same time: scored unsupported", unmatched);
  return support.summary();
}

// The paper's view: precision / recall summed over the steps up to the end of each second, the first 10.
// A second is labelled by the span of the clock it holds; one without a ground-truth step prints '-'.
void print_per_second(const std::vector<Report>& reports, const Options& options) {
  constexpr std::size_t kSeconds = 10;
  std::printf(
      "cumulative P / R at %.3g%% of the diagonal, over the steps up to the end of each second of the clock "
      "(counted from t0, the whole second before the first step; -: no step in that second):\n",
      options.tolerances.front() * 100);
  const auto number = [](double value) {
    return std::isfinite(value) ? fmt::format("{:.3f}", value) : std::string("n/a");
  };
  for (const Report& r : reports) {
    std::string row = fmt::format("{:<26}", r.label);
    const EvaluationReport& e = r.figures;
    if (e.seconds_origin) row += fmt::format(" t0 {:.0f} s:", static_cast<double>(*e.seconds_origin) * 1e-6);
    for (std::size_t k = 0; k < std::min(kSeconds, e.per_second.size()); ++k) {
      const StreamEvaluator::Second& second = e.per_second[k];
      row += fmt::format("  {}-{} s ", k, k + 1);
      row += second.steps == 0 ? std::string("-")
                               : number(second.cumulative.precision) + " / " + number(second.cumulative.recall);
    }
    std::printf("%s\n", row.c_str());
  }
}

void write_json(const std::vector<Report>& reports, const Options& options) {
  std::ofstream out(options.json);
  if (!out) throw std::runtime_error("cannot create " + options.json.string());
  JsonWriter json(out);
  json.begin_object().key("runs").begin_array();
  for (const Report& r : reports) {
    json.begin_object().key("run").value(r.label).key("fit_threshold");
    if (r.threshold) {
      json.value(static_cast<double>(*r.threshold));
    } else {
      json.null();
    }
    json.key("events")
        .value(r.events)
        .key("scene_seconds")
        .value(r.scene_seconds)
        .key("wall_seconds")
        .value(r.wall_seconds);
    write_evaluation_json(json, r.figures);
    if (r.support) write_support_json(json, *r.support);
    json.end_object();
  }
  json.end_array().end_object();
  if (!json.done()) throw std::logic_error("unbalanced JSON");
  out << "\n";
  if (!out) throw std::runtime_error("error writing " + options.json.string());
}

// Each run's chart gets its own file: the whole lines' NAME-whole.png, and with several runs
// (--pr-thresholds) NAME-f<threshold>.png.
std::filesystem::path run_path(const std::filesystem::path& path, const Report& report, bool several_runs) {
  std::string stem = path.stem().string();
  if (several_runs && report.threshold) stem += fmt::format("-f{:g}", static_cast<double>(*report.threshold));
  if (report.whole_lines) stem += "-whole";
  std::filesystem::path result = path;
  result.replace_filename(stem + path.extension().string());
  return result;
}

void write_run_plots(const Options& options, const StreamEvaluator& evaluator, const Report& report,
                     bool several_runs) {
  if (!options.lifetime_png.empty()) {
    write_histogram_png(run_path(options.lifetime_png, report, several_runs),
                        evaluator.lifetimes().histogram(options.histogram_bin_ms), options.histogram_bin_ms,
                        report.label + (report.whole_lines ? " whole-line lifetimes" : " segment lifetimes"));
  }
  if (!options.tracks_png.empty()) {
    write_id_timeline_png(run_path(options.tracks_png, report, several_runs), evaluator.tracking().lines(),
                          report.label + fmt::format(" ids over time (IDF1 {})", figure(report.figures.tracking.idf1)));
  }
  if (!options.edge_recall_png.empty() && evaluator.edge_recall()) {
    const auto path = run_path(options.edge_recall_png, report, several_runs);
    write_edge_recall_png(path, *evaluator.edge_recall(), report.label);
    spdlog::info("wrote {}", path.string());
  }
}

// --edge-recall: each run's recall by the true edges' speed, length and nearest parallel edge, and
// every edge at every step as CSV.
void write_edge_recall(const std::vector<Report>& reports, const std::filesystem::path& path) {
  std::ofstream out(path);
  out << edge_recall_csv_header();
  for (const Report& r : reports) {
    std::printf("\nrecall per true edge, %s (first tolerance):\n%s", r.label.c_str(),
                edge_recall_tables(r.edge_steps).c_str());
    out << edge_recall_csv_rows(r.label, r.edge_steps);
  }
  if (!out) throw std::runtime_error("error writing " + path.string());
  spdlog::info("wrote the recall of every true edge at every step to {}", path.string());
}

// No ground truth, --whole-lines: their support by the segments of the same run alone (a real recording).
int score_support_only(const Options& options) {
  const SupportSummary support = file_support(read_segments(options), read_segment_csv(options.whole_lines));
  print_support(options.whole_lines.filename().string(), support);
  if (!options.json.empty()) {
    std::ofstream out(options.json);
    JsonWriter json(out);
    json.begin_object();
    write_support_json(json, support);
    json.end_object();
    out << "\n";
    if (!json.done() || !out) throw std::runtime_error("error writing " + options.json.string());
  }
  return 0;
}

// --segments: a file of predicted segments against the ground truth.
int score_segment_file(const Options& options, const PipelineOptions& pipeline_options, const SimulatorOptions& sim,
                       std::vector<Report>& reports) {
  if (options.frames_gt.empty() && options.ground_truth.empty() == !sim.scene_selected()) {
    spdlog::error("with --segments give the ground truth: --ground-truth FILE, --scene NAME or --frames-gt SOURCE");
    return 1;
  }
  std::optional<SensorSize> sensor =
      sim.scene_selected() ? std::optional<SensorSize>(sim.scene().sensor) : pipeline_options.sensor();
  if (!sensor && !options.frames_gt.empty()) {
    sensor = frames_sensor_size(options.frames_gt, options.frames_topic);
    spdlog::info("sensor {}x{}: the size of the frames of {}", sensor->width, sensor->height,
                 options.frames_gt.string());
  }
  if (!sensor) {
    spdlog::error("give the sensor size (--width/--height or --config) for file-only evaluation without --frames-gt");
    return 1;
  }
  std::vector<SegmentRow> rows = read_segments(options);
  std::optional<SupportSummary> support;
  std::vector<SegmentRow> whole_line_rows;
  if (!options.whole_lines.empty()) {
    whole_line_rows = read_segment_csv(options.whole_lines);
    support = file_support(rows, whole_line_rows);
  }
  const std::vector<SegmentRow> overlay_rows = options.overlay.empty() ? std::vector<SegmentRow>() : rows;
  const StreamEvaluator scored = evaluate_files(options, std::move(rows), *sensor, sim);
  if (!options.overlay.empty()) write_overlay_pictures(options, scored, overlay_rows, whole_line_rows, *sensor);
  reports.push_back(make_report(scored));
  reports.back().label = options.label.empty() ? options.segments.filename().string() : options.label;
  reports.back().support = support;
  write_run_plots(options, scored, reports.back(), false);
  const StepCoverage& c = scored.coverage();
  spdlog::info(
      "{} ground-truth steps scored, {} of them with no prediction within {:.1f} ms; {} predicted steps, {} "
      "scored, {} outside the ground truth's time range (not scored)",
      c.ground_truth_steps, c.steps_without_prediction, static_cast<double>(scored.hold_us()) * 1e-3, c.predicted_steps,
      c.predicted_steps_scored, c.predicted_steps_outside);
  return 0;
}

// --scene without --segments: the pipeline on the scene, once per threshold, its segments and whole lines.
int score_scene_runs(const Options& options, const PipelineOptions& pipeline_options, const SimulatorOptions& sim,
                     std::vector<Report>& reports) {
  if (!sim.scene_selected()) {
    spdlog::error("give --segments FILE, or --scene NAME to run the pipeline on a built-in scene");
    return 1;
  }
  if ((!options.edge_recall.empty() || !options.edge_recall_png.empty()) && !options.frames_gt.empty()) {
    spdlog::error("--edge-recall needs the scene's exact edges: LSD's lines (--frames-gt) have no ids that last");
    return 1;
  }
  const Scene scene = sim.scene();
  const PipelineConfig base = pipeline_options.resolve(scene.sensor);
  std::vector<float> thresholds = options.pr_thresholds;
  if (thresholds.empty()) thresholds.push_back(base.score.fit_threshold);
  const GroundTruthSteps truth = ground_truth_steps(options, sim, scene.sensor);
  const Timestamp hold_us = StreamEvaluator::hold_for_period(options.step_us);
  for (const float threshold : thresholds) {
    PipelineConfig config = base;
    config.score.fit_threshold = threshold;
    const auto started = std::chrono::steady_clock::now();
    StreamEvaluator segments(scene.sensor, options.tolerances, truth, hold_us);
    StreamEvaluator whole(scene.sensor, options.tolerances, truth, hold_us);
    if (!options.edge_recall.empty() || !options.edge_recall_png.empty()) {
      const Timestamp middle = truth.times.empty() ? 0 : truth.times[truth.times.size() / 2];
      segments.keep_edge_recall(middle);
      whole.keep_edge_recall(middle);
    }
    if (options.visible_only) {
      segments.score_visible_only(VisibleOnly::by_speed(options.min_normal_speed));
      whole.score_visible_only(VisibleOnly::by_speed(options.min_normal_speed));
    }
    const SceneRunResult result =
        evaluate_scene(scene, sim.config(), config, options.step_us, segments, &whole, options.thin);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    spdlog::info("{} f_th={}: {} events, {:.2f} s wall", scene.name, threshold, result.events, wall);
    for (const auto& [evaluator, label] :
         {std::pair<const StreamEvaluator*, std::string>{&segments, scene.name}, {&whole, scene.name + " whole"}}) {
      Report r = make_report(*evaluator);
      r.label = label;
      r.whole_lines = evaluator == &whole;
      r.threshold = threshold;
      r.events = result.events;
      r.scene_seconds = result.scene_seconds;
      r.wall_seconds = wall;
      if (r.whole_lines) r.support = result.whole_line_support;
      write_run_plots(options, *evaluator, r, thresholds.size() > 1);
      reports.push_back(r);
    }
  }
  if (!options.frames_gt.empty()) {
    // How good the imitation is: LSD's lines on the frames, scored against the scene's exact lines.
    const StreamEvaluator lsd = evaluate_steps_against(truth, scene_ground_truth_steps(scene, options.step_us),
                                                       scene.sensor, options.tolerances);
    Report r = make_report(lsd);
    r.label = scene.name + " lsd/exact";
    reports.push_back(r);
  }
  return 0;
}

// Every report as the options ask: the table and its companions, then the files.
void print_and_write(const std::vector<Report>& reports, const Options& options) {
  print_table(reports, options);
  print_switch_causes(reports);
  for (const Report& r : reports) {
    if (r.support) print_support(r.label, *r.support);
  }
  if (options.visible_only) print_visible(reports, options);
  if (options.per_second) print_per_second(reports, options);
  if (!options.edge_recall.empty()) write_edge_recall(reports, options.edge_recall);
  if (!options.json.empty()) write_json(reports, options);
  if (!options.pr_png.empty()) {
    std::vector<PrPoint> points;
    points.reserve(reports.size());
    for (const Report& r : reports)
      points.push_back({r.threshold.value_or(0.0f), r.figures.accuracy[0].precision, r.figures.accuracy[0].recall,
                        r.figures.accuracy[0].f});
    write_pr_curve_png(options.pr_png, points,
                       reports.front().label + " PR over f_th (tolerance " +
                           std::to_string(options.tolerances[0] * 100).substr(0, 3) + "% of diagonal)");
  }
}

int run(const Options& options, const PipelineOptions& pipeline_options, const SimulatorOptions& sim) {
  if (!options.whole_lines.empty() && options.segments.empty()) {
    spdlog::error("--whole-lines is scored against the segments of the same run: give --segments too");
    return 1;
  }
  if (!options.whole_lines.empty() && options.ground_truth.empty() && options.frames_gt.empty() &&
      !sim.scene_selected()) {
    return score_support_only(options);
  }
  if ((!options.edge_recall.empty() || !options.edge_recall_png.empty()) && !options.segments.empty()) {
    spdlog::error("--edge-recall scores the pipeline's run on --scene (without --segments)");
    return 1;
  }
  if (options.visible_only && !options.frames_gt.empty() && options.segments.empty()) {
    spdlog::error(
        "--visible-only with --frames-gt scores a recording's --segments: LSD's lines are seen by its events");
    return 1;
  }
  if (!options.overlay.empty() && (options.segments.empty() || options.frames_gt.empty())) {
    spdlog::error("--overlay draws the frames of --frames-gt with the lines of --segments: give both");
    return 1;
  }
  std::vector<Report> reports;
  const int status = options.segments.empty() ? score_scene_runs(options, pipeline_options, sim, reports)
                                              : score_segment_file(options, pipeline_options, sim, reports);
  if (status != 0) return status;
  print_and_write(reports, options);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "evldt-eval: line heat-map precision/recall/F (pixels matched one-to-one within a tolerance of the\n"
      "image diagonal, counts summed over steps) and segment lifetimes. Either score a segment CSV\n"
      "against --ground-truth CSV or a --scene, or run the pipeline on --scene (with --pr-thresholds, once per f_th);\n"
      "a pipeline run is scored twice: its block segments, and its whole lines (row \"SCENE whole\"), whose\n"
      "support by the segments is measured too (as --whole-lines does for files, without ground truth).\n"
      "Every ground-truth step is scored, against the latest predicted step at or before it within 1.5 output\n"
      "periods, else against nothing (its ground truth counts as missed). Undefined figures print n/a.\n"
      "Tracking, at the first tolerance: a predicted segment matches the true line within the tolerance of at\n"
      "least half its length; cover = matched share of the true lines' steps, ids/gt = distinct ids per true\n"
      "line, id_sw = changes of the id that stands for a line, IDF1 = identity F1 over lengths (one id per line)."};
  Options options;
  PipelineOptions pipeline_options;
  SimulatorOptions sim_options;
  app.add_option("--segments", options.segments,
                 "Predicted segments: CSV (from evldt-offline) or an lcm-log with segment lists")
      ->check(CLI::ExistingFile);
  app.add_option("--whole-lines", options.whole_lines,
                 "Whole lines (evldt-offline --whole-lines) of the run --segments comes from: their support by its "
                 "segments (share of their length within 2 px of a segment of the same step); no ground truth needed")
      ->check(CLI::ExistingFile);
  app.add_option(
      "--lcm-channel", options.lcm_channel,
      "Segment channel of an lcm-log (default: the first LINES_*; WHOLE_LINES_<CAMERA> for the whole lines)");
  app.add_option("--label", options.label, "Name of the --segments row (default: the file's name)");
  app.add_option("--ground-truth", options.ground_truth, "Ground-truth CSV (from evldt-sim)")->check(CLI::ExistingFile);
  app.add_option(
         "--frames-gt", options.frames_gt,
         "Ground truth as the paper makes it: LSD on the intensity frames of this ECD folder (images.txt and "
         "images/; evldt-sim --frames-hz writes one), ROS 1 or 2 bag (.bag, .db3, .mcap) (sensor_msgs/Image: mono8, "
         "mono16, bgr8, rgb8), "
         "MVSEC HDF5 file, AEDAT 4.0, 3.1 or 2.0 (jAER DAVIS) recording or video file, in place of the exact lines")
      ->check(CLI::ExistingPath);
  app.add_option(
      "--frames-topic", options.frames_topic,
      "With --frames-gt a bag: its image topic (default: the first sensor_msgs/Image); an HDF5 file: its frame "
      "dataset (default: /davis/left/image_raw)");
  app.add_option("--write-gt", options.write_gt,
                 "Write the ground truth scored against (LSD's lines with --frames-gt) as a CSV like evldt-sim's "
                 "(t_us,gt_id,x0,y0,x1,y1), for --ground-truth of other runs");
  app.add_flag(
      "--per-second", options.per_second,
      "Also print the paper's view: precision and recall summed up to each second, over the first 10 s (the JSON "
      "has every second)");
  app.add_flag(
      "--visible-only", options.visible_only,
      "Also score against what an events-only camera can see: simulated true edges (--scene, or evldt-sim's "
      "ground-truth CSV) where they move across themselves at --min-normal-speed or more; with --frames-gt, LSD's "
      "lines along which the recording's events fell (--support-window-ms); predicted pixels left unmatched near "
      "the others count neither way. A second row per run; the full one stays the headline");
  app.add_option("--min-normal-speed", options.min_normal_speed, "With --visible-only: px/s (default 2)")
      ->check(CLI::Range(0.0f, 1e6f));
  app.add_option("--events", options.events,
                 "With --visible-only and --frames-gt: the recording whose events go with the frames (default: the "
                 "--frames-gt file itself, or the events.txt of its folder)");
  app.add_option_function<double>(
         "--support-window-ms",
         [&](double ms) { options.support.half_window_us = static_cast<Timestamp>(std::llround(ms * 1000)); },
         "With --visible-only and --frames-gt: a LSD line is seen where half or more of its pixels have an event in "
         "the "
         "3 x 3 pixels around them within this of the frame's time (default 10)")
      ->check(CLI::Range(0.1, 10000.0));
  app.add_option("--lsd-min-length", options.lsd.min_length_px,
                 "With --frames-gt: LSD segments shorter than this (px) are dropped")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.0, 10000.0));
  sim_options.add_to(app, /*scene_required=*/false);
  app.add_option("--tolerance", options.tolerances, "Match tolerances as fractions of the diagonal")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.0001, 0.5));
  app.add_option("--step-us", options.step_us,
                 "With --scene: event time between ground-truth steps (and pipeline outputs)")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{100}, Timestamp{10'000'000}));
  app.add_option(
         "--thin", options.thin,
         "Scene runs: a service past its means: every batch thinned to every K-th event (ending with its last) and\n"
         "stored as evldt-lines stores a batch it thinned, each kept event K / 2 times, at least once (1: none)")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  app.add_option(
         "--output-period-us", options.output_period_us,
         "Output period of --segments (default: its median step spacing); a predicted step is held for 1.5 periods")
      ->check(CLI::Range(Timestamp{1}, Timestamp{10'000'000}));
  app.add_option("--pr-thresholds", options.pr_thresholds, "Scene runs: f_th values for a PR curve")
      ->check(finite_number() & CLI::Range(0.0, 1.0));
  app.add_option("--json", options.json, "Write the results as JSON");
  app.add_option("--overlay", options.overlay,
                 "With --segments and --frames-gt: a folder of one PNG per scored frame, the frame with LSD's lines\n"
                 "(green), the segments held at its time (red) and the --whole-lines (blue)");
  app.add_option("--pr-png", options.pr_png, "Plot precision/recall over the thresholds (first tolerance)");
  app.add_option("--edge-recall", options.edge_recall,
                 "Scene runs: print the recall by the true edges' speed across themselves, length and distance to the "
                 "nearest parallel edge, and write every true edge at every step to this CSV "
                 "(run,t_us,gt_id,length_px,normal_speed_px_s,parallel_gap_px,pixels,matched)");
  app.add_option(
      "--edge-recall-png", options.edge_recall_png,
      "Scene runs: a picture of the middle ground-truth step, its true edges green where found and red where "
      "missed, the prediction in blue (the whole lines' run in NAME-whole.png)");
  app.add_option("--lifetime-png", options.lifetime_png,
                 "Histogram of segment lifetimes (with --pr-thresholds one file per run, NAME-f<threshold>.png)");
  app.add_option(
      "--tracks-png", options.tracks_png,
      "Ids over time: a row per true line, coloured by the predicted id that stood for it (per run, as above)");
  app.add_option("--lifetime-bin-ms", options.histogram_bin_ms, "Histogram bin width")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.1, 1e6));
  pipeline_options.add_to(app);
  return run_main(app, argc, argv, [&] { return run(options, pipeline_options, sim_options); });
}
