// evldt-offline: the deterministic pipeline over a recording, a scene or a video, writing segments over time as CSV,
// a summary, and optionally a rendered video or PNG frames.

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/app/run_summary.hpp"
#include "evldt/app/source_options.hpp"
#include "evldt/events/event_validator.hpp"
#include "evldt/pipeline/deterministic_pipeline.hpp"
#include "evldt/pipeline/segment_csv.hpp"
#include "evldt/render/frame_writer.hpp"
#include "evldt/render/line_picture.hpp"
#include "evldt/sources/read_ahead.hpp"

namespace {

using namespace evldt;
using Clock = std::chrono::steady_clock;

struct Options {
  std::filesystem::path output = "segments.csv";
  std::filesystem::path whole_lines;
  Timestamp output_period_us = 10000;
  std::filesystem::path summary_json;
  std::filesystem::path video;
  std::filesystem::path frames_dir;
  Timestamp render_period_us = 33333;
  RenderOptions render{.scale = 2};
  bool quiet = false;
};

// Renders output steps to an mp4 and/or PNG files, at most once per render period of event time.
class FrameSink {
 public:
  FrameSink(const Options& options, SensorSize sensor)
      : period_us_(options.render_period_us),
        sensor_(sensor),
        render_(options.render),
        writer_(options.video, options.frames_dir, 1e6 / static_cast<double>(options.render_period_us),
                cv::Size(sensor.width * options.render.scale, sensor.height * options.render.scale)) {}
  [[nodiscard]] bool enabled() const { return writer_.enabled(); }
  /// Whether the frames need the whole lines.
  [[nodiscard]] bool draws_whole_lines() const { return enabled() && render_.show_whole_lines; }

  void step(Timestamp t, const LineMap& lines, std::span<const TrackedLine> whole_lines, const ScarfLattice& lattice) {
    if (!enabled() || t < next_render_) return;
    next_render_ = t + period_us_;
    picture_.draw(sensor_, lattice.surface(), lines.lines(), whole_lines, render_, canvas_);
    writer_.write(canvas_);
  }
  [[nodiscard]] int frames() const { return writer_.frames(); }

 private:
  Timestamp period_us_;
  SensorSize sensor_;
  RenderOptions render_;
  LinePicture picture_;
  FrameWriter writer_;
  cv::Mat canvas_;
  Timestamp next_render_ = 0;
};

int run(const Options& options, const PipelineOptions& pipeline_options, const SourceOptions& source_options) {
  const std::atomic<bool> never_stop{false};  // a live input is read to its end (Ctrl-C ends the process)
  const std::unique_ptr<EventSource> opened = source_options.open(pipeline_options.time_slack_us(), never_stop);
  EventSource& source = *opened;
  const auto sensor = pipeline_options.sensor() ? pipeline_options.sensor() : source.geometry();
  if (!sensor) {
    spdlog::error("{} has no sensor size in its header: pass --width and --height, or --config config/<size>.toml",
                  source.name());
    return 1;
  }
  const PipelineConfig config = pipeline_options.resolve(*sensor);
  EventValidator validator(*sensor, pipeline_options.time_slack_us());
  FrameSink frames(options, *sensor);
  DeterministicPipeline pipeline(config, /*keep_surface=*/frames.enabled());
  SegmentCsvWriter csv(options.output);
  std::optional<SegmentCsvWriter> whole_csv;
  if (!options.whole_lines.empty()) whole_csv.emplace(options.whole_lines);
  pipeline.set_output(
      options.output_period_us,
      [&](const OutputStep& step) {
        csv.write_step(step.t, step.segments.lines());
        if (whole_csv) whole_csv->write_step(step.t, step.whole_lines);
        frames.step(step.t, step.segments, step.whole_lines, step.lattice);
      },
      /*whole_lines=*/whole_csv || frames.draws_whole_lines());

  spdlog::info("{}: {}x{}, b={} N={} dq={} f_th={}", source.name(), sensor->width, sensor->height,
               config.lattice.block_size, pipeline.lattice().geometry().capacity, config.track.perturbation_px,
               config.score.fit_threshold);

  RunSummary summary;
  summary.input = source.name();
  const auto started = Clock::now();
  auto last_progress = started;
  std::optional<Timestamp> first_t;
  Timestamp newest_t = 0;
  {
    // Reading, decoding, validating and filtering on a thread of their own, a few batches ahead of
    // storage and the rounds (the same output: the pipeline sees the same batches in the same order).
    ReadAhead reader(source, [&](EventBatch& batch, EventBatch& filtered) {
      validator.filter(batch);
      pipeline.filter(batch, filtered);
    });
    try {
      while (const ReadAhead::Item* item = reader.next()) {
        summary.events_read += item->events_read;
        if (!item->batch.empty()) {
          if (!first_t) first_t = item->batch.t.front();
          newest_t = item->batch.t.back();
        }
        pipeline.process_filtered(item->batch, item->prepared);
        if (!options.quiet && Clock::now() - last_progress > std::chrono::seconds(2)) {
          last_progress = Clock::now();
          spdlog::info("progress: {:.0f}%, {} events, {:.2f} s of event time, {} live lines", 100.0 * item->progress,
                       summary.events_read, static_cast<double>(newest_t - first_t.value_or(0)) * 1e-6,
                       pipeline.lines().lines().size());
        }
      }
    } catch (const FormatError& error) {
      spdlog::error("{} (every event before it was processed)", error.what());
      summary.input_error = error.what();
    }
  }
  csv.close();
  if (whole_csv) {
    whole_csv->close();
    summary.whole_lines_path = options.whole_lines.string();
    summary.whole_lines_created = pipeline.whole_lines()->created();
    summary.whole_line_rows = whole_csv->rows();
  }

  summary.wall_seconds = std::chrono::duration<double>(Clock::now() - started).count();
  summary.event_seconds = first_t ? static_cast<double>(validator.newest_time() - *first_t) * 1e-6 : 0.0;
  summary.drops = validator.drops();
  summary.decoded = source.decode_counts();
  summary.add_pipeline(pipeline);
  summary.csv_rows = csv.rows();
  summary.frames = frames.frames();
  summary.print(stdout, options.output.string());
  if (!options.summary_json.empty()) summary.write_json(options.summary_json);
  return summary.input_error.empty() ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "evldt-offline: detect and track line segments in an event recording or a built-in scene, deterministically.\n"
      "Writes the segments over time as CSV (t_us,id,x0,y0,x1,y1,score,status,normal_velocity,normal_velocity_std)\n"
      "and prints a summary.\n"
      "Exit status: 0 done, 1 bad usage or configuration, 2 corrupt input (events before the fault processed)."};
  Options options;
  PipelineOptions pipeline_options;
  SourceOptions source_options;
  source_options.add_to(app);
  app.add_option("-o,--output", options.output, "Segment CSV to write")->capture_default_str();
  app.add_option(
      "--whole-lines", options.whole_lines,
      "Also write whole lines (collinear touching segments joined, with their own ids) as CSV in the segment "
      "format: score = segments joined, status good");
  app.add_option("--output-period-us", options.output_period_us, "Event time between CSV rows of segments")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{1}, Timestamp{60'000'000}));
  app.add_option("--summary-json", options.summary_json, "Also write the summary as JSON");
  app.add_option("--video", options.video, "Render an mp4 of events, segments and whole lines");
  app.add_option("--frames", options.frames_dir, "Render PNG frames into this directory");
  app.add_option("--render-period-us", options.render_period_us, "Event time between rendered frames")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{1}, Timestamp{60'000'000}));
  app.add_option("--render-scale", options.render.scale, "Zoom of rendered frames")
      ->capture_default_str()
      ->check(CLI::Range(1, 8));
  app.add_flag("!--no-whole-lines", options.render.show_whole_lines, "Rendered frames without the whole lines");
  app.add_flag("!--no-ids", options.render.show_whole_line_ids, "Rendered frames without the whole lines' ids");
  app.add_flag("--segment-ids", options.render.show_segment_ids, "Write the segments' ids on rendered frames too");
  app.add_flag("-q,--quiet", options.quiet, "No progress lines");
  pipeline_options.add_to(app);
  return run_main(app, argc, argv, [&] { return run(options, pipeline_options, source_options); });
}
