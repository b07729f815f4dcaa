// evldt-camera: publishes event batches from a recording, a built-in scene or a video on
// EVENTS_<CAMERA>, paced at real time or a speed factor, and its statistics on EVLDT_STATS.

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "evldt/app/lcm_options.hpp"
#include "evldt/app/pipeline_options.hpp"
#include "evldt/app/source_options.hpp"
#include "evldt/nodes/camera_node.hpp"
#include "evldt/pipeline/thread_name.hpp"
#include "evldt/transport/channels.hpp"

int main(int argc, char** argv) {
  using namespace evldt;
  CLI::App app{
      "evldt-camera: publish camera events over LCM on EVENTS_<CAMERA> (evldt.event_batch_t), and its\n"
      "statistics (evldt.stats_t, once a second: events, drops, words the decoder skipped) on EVLDT_STATS.\n"
      "Sources: a recording in any format evldt reads (see input), a built-in --scene, or\n"
      "--from-video FILE|WEBCAM_INDEX by frame differencing; live, as a camera records: '-' (standard\n"
      "input), tcp://HOST:PORT, or --follow FILE while a recorder writes it (events go out as they come,\n"
      "unpaced). Prints progress and a summary.\n"
      "Exit status: 0 done or stopped by SIGINT/SIGTERM, 1 bad usage or setup, 2 corrupt input."};
  LcmOptions lcm_options;
  SourceOptions source_options;
  CameraNodeOptions options;
  std::optional<int> width, height;
  bool quiet = false;
  lcm_options.add_to(app);
  source_options.add_to(app);
  app.add_option("--speed", options.speed, "Replay speed factor (1 = real time, 0 = as fast as possible)")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.0, 1000.0));
  app.add_flag("--loop", options.loop, "Replay the source forever (event time keeps increasing)");
  app.add_option("--batch-us", options.batch_us, "Event time per batch")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{1}, Timestamp{1'000'000}));
  app.add_option("--max-batch", options.max_batch, "Most events per batch (7000 = one 64 KiB datagram)")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{1'000'000}));
  app.add_option("--width", width, "Sensor width, where the recording does not say")
      ->check(CLI::Range(1, kMaxSensorSide));
  app.add_option("--height", height, "Sensor height, where the recording does not say")
      ->check(CLI::Range(1, kMaxSensorSide));
  app.add_option("--time-slack-us", options.time_slack_us, "Events older than the newest by more are dropped")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{0}, Timestamp{10'000'000}));
  app.add_flag("-q,--quiet", quiet, "No progress lines");
  return run_main(app, argc, argv, [&] {
    if (width.has_value() != height.has_value()) throw std::invalid_argument("give --width and --height together");
    if (width) options.sensor = SensorSize{*width, *height};
    options.camera = lcm_options.camera();
    if (quiet) options.progress_period_s = 0;
    const auto& stop = stop_on_signals();
    // Reading, batching and publishing run above normal work (the subscribers' rounds on this
    // host): a camera that falls behind catches up in a burst, which overflows socket buffers.
    if (!raise_this_thread_for_ingest()) {
      spdlog::info("publishing runs at normal priority: raising it needs CAP_SYS_NICE (README, real time)");
    }
    const auto lcm = lcm_options.connect();
    CameraNode node(*lcm, options, process_epoch_us());
    announce_ready("evldt-camera",
                   fmt::format("publishing on {} ({})", events_channel(options.camera), lcm_options.effective_url()));
    const CameraSummary summary = node.run([&] { return source_options.open(options.time_slack_us, stop); }, stop);
    summary.print(stdout);
    return summary.input_error.empty() ? 0 : 2;
  });
}
