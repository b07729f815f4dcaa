// evldt-offline: the deterministic pipeline over a recording, writing segments over time as CSV,
// a summary, and optionally a rendered video or PNG frames.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <spdlog/spdlog.h>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/app/run_summary.hpp"
#include "evldt/app/simulator_options.hpp"
#include "evldt/events/event_reader.hpp"
#include "evldt/events/event_validator.hpp"
#include "evldt/lines/deterministic_pipeline.hpp"
#include "evldt/lines/segment_csv.hpp"
#include "evldt/render/scene_renderer.hpp"
#include "evldt/sim/event_simulator.hpp"

namespace {

using namespace evldt;
using Clock = std::chrono::steady_clock;

struct Options {
  std::filesystem::path input;
  std::string format;
  std::filesystem::path output = "segments.csv";
  Timestamp output_period_us = 10000;
  std::filesystem::path summary_json;
  std::filesystem::path video;
  std::filesystem::path frames_dir;
  Timestamp render_period_us = 33333;
  int render_scale = 2;
  bool show_ids = false;
  bool quiet = false;
};

// Renders output steps to an mp4 and/or PNG files, at most once per render period of event time.
class FrameSink {
 public:
  FrameSink(const Options& options, SensorSize sensor) : options_(options), sensor_(sensor) {
    render_.scale = options.render_scale;
    render_.show_ids = options.show_ids;
    const cv::Size size(sensor.width * render_.scale, sensor.height * render_.scale);
    if (!options.video.empty()) {
      const double fps = 1e6 / static_cast<double>(options.render_period_us);
      if (!video_.open(options.video.string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps, size)) {
        throw std::runtime_error("cannot open video writer for " + options.video.string());
      }
    }
    if (!options.frames_dir.empty()) std::filesystem::create_directories(options.frames_dir);
  }
  [[nodiscard]] bool enabled() const { return video_.isOpened() || !options_.frames_dir.empty(); }

  void step(Timestamp t, const LineMap& lines, const ScarfLattice& lattice) {
    if (!enabled() || t < next_render_) return;
    next_render_ = t + options_.render_period_us;
    render_scene(sensor_, lattice.surface(), lines.lines(), render_, canvas_);
    if (video_.isOpened()) video_.write(canvas_);
    if (!options_.frames_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%06d.png", frames_);
      if (!cv::imwrite((options_.frames_dir / name).string(), canvas_)) {
        throw std::runtime_error("cannot write " + (options_.frames_dir / name).string());
      }
    }
    ++frames_;
  }
  [[nodiscard]] int frames() const { return frames_; }

 private:
  const Options& options_;
  SensorSize sensor_;
  RenderOptions render_;
  cv::VideoWriter video_;
  cv::Mat canvas_;
  Timestamp next_render_ = 0;
  int frames_ = 0;
};

// Where events come from: a recording file or a built-in simulated scene.
class EventSource {
 public:
  EventSource(const Options& options, const SimulatorOptions& sim_options) {
    if (sim_options.scene_selected()) {
      simulator_.emplace(sim_options.scene(), sim_options.config());
      name_ = "scene " + sim_options.scene_name();
      return;
    }
    std::optional<EventFormat> format;
    if (!options.format.empty()) format = parse_event_format(options.format);
    reader_.emplace(options.input, format);
    name_ = options.input.string() + " (" + std::string(format_name(reader_->format())) + ")";
  }
  /// Clears `batch` and fills it with the next events; false at the end.
  bool read(EventBatch& batch) {
    if (reader_) return reader_->read(batch);
    batch.clear();
    constexpr Timestamp kSliceUs = 10000;
    return simulator_->run_until(simulator_->now_us() + kSliceUs, batch);
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const {
    return reader_ ? reader_->geometry() : std::optional<SensorSize>(simulator_->scene().sensor);
  }
  [[nodiscard]] double progress() const {
    if (reader_) return static_cast<double>(reader_->bytes_read()) / static_cast<double>(std::max<std::uint64_t>(1, reader_->file_size()));
    return static_cast<double>(simulator_->now_us()) / static_cast<double>(simulator_->scene().duration_us);
  }
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  std::optional<EventFileReader> reader_;
  std::optional<EventSimulator> simulator_;
  std::string name_;
};

int run(const Options& options, const PipelineOptions& pipeline_options, const SimulatorOptions& sim_options) {
  if (options.input.empty() == !sim_options.scene_selected()) {
    spdlog::error("give either a recording file or --scene NAME (not both)");
    return 1;
  }
  EventSource source(options, sim_options);
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
  pipeline.set_output(options.output_period_us, [&](Timestamp t, const LineMap& lines, const ScarfLattice& lattice) {
    csv.write_step(t, lines.lines());
    frames.step(t, lines, lattice);
  });

  spdlog::info("{}: {}x{}, b={} N={} dq={} f_th={}", source.name(), sensor->width, sensor->height, config.lattice.block_size, pipeline.lattice().geometry().capacity,
               config.track.perturbation_px, config.score.fit_threshold);

  RunSummary summary;
  summary.input = source.name();
  const auto started = Clock::now();
  auto last_progress = started;
  EventBatch batch;
  std::optional<Timestamp> first_t;
  try {
    while (source.read(batch)) {
      summary.events_read += batch.size();
      validator.filter(batch);
      if (!batch.empty() && !first_t) first_t = batch.t.front();
      pipeline.process(batch);
      if (!options.quiet && Clock::now() - last_progress > std::chrono::seconds(2)) {
        last_progress = Clock::now();
        spdlog::info("progress: {:.0f}%, {} events, {:.2f} s of event time, {} live lines",
                     100.0 * source.progress(),
                     summary.events_read, static_cast<double>(validator.newest_time() - first_t.value_or(0)) * 1e-6,
                     pipeline.lines().lines().size());
      }
    }
  } catch (const FormatError& error) {
    spdlog::error("{} (every event before it was processed)", error.what());
    summary.input_error = error.what();
  }
  csv.close();

  summary.wall_seconds = std::chrono::duration<double>(Clock::now() - started).count();
  summary.event_seconds = first_t ? static_cast<double>(validator.newest_time() - *first_t) * 1e-6 : 0.0;
  summary.drops = validator.drops();
  summary.counters = pipeline.counters();
  summary.add_lines(pipeline.lines());
  summary.csv_rows = csv.rows();
  summary.frames = frames.frames();
  summary.print(stdout, options.output.string());
  if (!options.summary_json.empty()) summary.write_json(options.summary_json);
  return summary.input_error.empty() ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"evldt-offline: detect and track line segments in an event recording or a built-in scene, deterministically.\n"
               "Writes the segments over time as CSV (t_us,id,x0,y0,x1,y1,score,status) and prints a summary.\n"
               "Exit status: 0 done, 1 bad usage or configuration, 2 corrupt input (events before the fault processed)."};
  Options options;
  PipelineOptions pipeline_options;
  SimulatorOptions sim_options;
  app.add_option("input", options.input, "Recording: ECD events.txt, Prophesee RAW (EVT 2.0/3.0) or .dat")
      ->check(CLI::ExistingFile);
  sim_options.add_to(app, /*scene_required=*/false);
  app.add_option("--format", options.format, "Input format when the name does not tell: ecd, evt2, evt3, dat")
      ->check(CLI::IsMember({"ecd", "evt2", "evt3", "dat"}));
  app.add_option("-o,--output", options.output, "Segment CSV to write")->capture_default_str();
  app.add_option("--output-period-us", options.output_period_us, "Event time between CSV rows of segments")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{1}, Timestamp{60'000'000}));
  app.add_option("--summary-json", options.summary_json, "Also write the summary as JSON");
  app.add_option("--video", options.video, "Render an mp4 of events and segments");
  app.add_option("--frames", options.frames_dir, "Render PNG frames into this directory");
  app.add_option("--render-period-us", options.render_period_us, "Event time between rendered frames")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{1}, Timestamp{60'000'000}));
  app.add_option("--render-scale", options.render_scale, "Zoom of rendered frames")->capture_default_str()->check(CLI::Range(1, 8));
  app.add_flag("--show-ids", options.show_ids, "Write line ids on rendered frames");
  app.add_flag("-q,--quiet", options.quiet, "No progress lines");
  pipeline_options.add_to(app);
  return run_main(app, argc, argv, [&] { return run(options, pipeline_options, sim_options); });
}
