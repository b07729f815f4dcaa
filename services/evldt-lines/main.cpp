// evldt-lines: SCARF storage, line detection and tracking on one camera's events from LCM;
// publishes the live segments on LINES_<CAMERA> and its statistics on EVLDT_STATS.

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>

#include "evldt/app/lcm_options.hpp"
#include "evldt/app/pipeline_options.hpp"
#include "evldt/nodes/lines_node.hpp"
#include "evldt/pipeline/thread_name.hpp"
#include "evldt/transport/channels.hpp"

int main(int argc, char** argv) {
  using namespace evldt;
  CLI::App app{
      "evldt-lines: detect and track line segments in real time from EVENTS_<CAMERA> (LCM).\n"
      "Publishes evldt.segment_list_t on LINES_<CAMERA> at --publish-hz and evldt.stats_t on EVLDT_STATS\n"
      "once a second. The sensor size comes from the first batch unless --width/--height or --config set it (then the\n"
      "lattice and filters are built at start, and the first batches do not queue behind them).\n"
      "Runs until SIGINT/SIGTERM, then prints a summary."};
  LcmOptions lcm_options;
  PipelineOptions pipeline_options;
  LinesNodeOptions options;
  lcm_options.add_to(app);
  app.add_option("--publish-hz", options.publish_hz,
                 "Segment lists per second at most: one after each round that changed the lines, and an unchanged one "
                 "once a second")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.1, 10000.0));
  app.add_option("--max-latency-ms", options.max_latency_ms,
                 "Latency budget: event batches that queued longer than this before they could be stored keep every "
                 "2nd event (every 4th past 1.5 times it) and are shed whole, unstored, past twice it (counted; their "
                 "time still moves the rounds on); with --overload shed they are shed past it. 0: never thin nor shed")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.0, 3600000.0));
  app.add_option("--overload", options.overload,
                 "What a batch that queued past the latency budget meets: thin (a share of its events kept, evenly; "
                 "shed past twice the budget) or shed (the whole batch, unstored)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, OverloadPolicy>{{"thin", OverloadPolicy::Thin}, {"shed", OverloadPolicy::Shed}}))
      ->default_str("thin");
  app.add_option("--stats-hz", options.stats_hz, "Statistics messages per second")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.01, 100.0));
  app.add_flag("--whole-lines,!--no-whole-lines", options.whole_lines,
               "Also publish whole lines (collinear touching segments joined, own ids) on WHOLE_LINES_<CAMERA>")
      ->capture_default_str();
  app.add_option("--whole-lines-hz", options.whole_lines_hz,
                 "Whole-line lists per second at most (each goes with a segment list)")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.1, 10000.0));
  app.add_option("--whole-lines-loaded-hz", options.whole_lines_loaded_hz,
                 "Whole-line lists per second at most while batches are being shed (until none has been for 1 s): "
                 "the tracking rounds get the CPU first")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.1, 10000.0));
  app.add_option("--log-period-s", options.log_period_s, "A status line in the log this often (0: never)")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.0, 3600.0));
  pipeline_options.add_to(app);
  return run_main(app, argc, argv, [&] {
    options.camera = lcm_options.camera();
    options.sensor = pipeline_options.sensor();
    options.time_slack_us = pipeline_options.time_slack_us();
    // The last sensor's configuration is kept: with a calibration, resolving builds a per-pixel table
    // (a tenth of a second at 1280x720), which the check at start, the sensor check of the first
    // batch and the engine would otherwise each build again. Called from one thread at a time.
    std::optional<PipelineConfig> resolved;
    options.configure = [&](SensorSize sensor) {
      if (!resolved || !(resolved->lattice.sensor == sensor)) resolved = pipeline_options.resolve(sensor);
      return *resolved;
    };
    if (options.sensor) (void)options.configure(*options.sensor);  // a bad value fails now, not at the first batch
    const auto& stop = stop_on_signals();
    // This thread handles LCM and starts the store thread: both above the rounds, which must take
    // what the cores have left, not delay storage.
    if (!raise_this_thread_for_ingest()) {
      spdlog::info("storage runs at the rounds' priority: raising it needs CAP_SYS_NICE (README, real time)");
    }
    const auto lcm = lcm_options.connect();
    LinesNode node(*lcm, options, process_epoch_us());
    announce_ready("evldt-lines",
                   fmt::format("listening on {} ({}), publishing {} at {} Hz", events_channel(options.camera),
                               lcm_options.effective_url(), lines_channel(options.camera), options.publish_hz));
    node.run(stop);
    node.totals().print(stdout, options);
    return 0;
  });
}
