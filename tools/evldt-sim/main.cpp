// evldt-sim: renders a built-in scene into event recordings plus exact ground-truth segments.

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <memory>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/app/simulator_options.hpp"
#include "evldt/events/event_writer.hpp"
#include "evldt/frames/frame_writer.hpp"
#include "evldt/sim/ground_truth_csv.hpp"
#include "evldt/sim/scenes.hpp"

namespace {

using namespace evldt;

std::filesystem::path file_for(EventFormat format) {
  switch (format) {
    case EventFormat::EcdText:
      return "events.txt";
    case EventFormat::Evt2:
      return "events_evt2.raw";
    case EventFormat::Evt3:
      return "events.raw";
    case EventFormat::Evt21:
      return "events_evt21.raw";
    case EventFormat::Dat:
      return "events.dat";
    case EventFormat::Aedat2:
    case EventFormat::Aedat31:
    case EventFormat::Aedat31Network:
    case EventFormat::EventStream:
      break;  // not written
  }
  return "events";
}

int run(const SimulatorOptions& sim_options, const std::filesystem::path& out_dir,
        const std::vector<std::string>& formats, Timestamp gt_period_us, double frames_hz, const ApsModel& aps,
        bool quiet) {
  const Scene scene = sim_options.scene();
  std::filesystem::create_directories(out_dir);
  std::vector<std::unique_ptr<EventWriter>> writers;
  std::vector<std::filesystem::path> written;
  for (const std::string& name : formats) {
    const EventFormat format = *parse_event_format(name);
    written.push_back(out_dir / file_for(format));
    writers.push_back(std::make_unique<EventWriter>(written.back(), format, scene.sensor));
  }
  written.push_back(out_dir / "ground_truth.csv");
  GroundTruthCsvWriter ground_truth(written.back());

  EventSimulator simulator(scene, sim_options.config());
  const auto started = std::chrono::steady_clock::now();
  auto last_progress = started;
  EventBatch batch;
  std::uint64_t events = 0;
  // Ground truth at t = 0, gt_period, ...; events are generated up to each GT time in turn.
  for (Timestamp t = 0; t <= scene.duration_us; t += gt_period_us) {
    batch.clear();
    simulator.run_until(t, batch);
    for (auto& writer : writers) writer->write(batch);
    events += batch.size();
    ground_truth.write_step(t, scene.visible_edges(t));
    if (!quiet && std::chrono::steady_clock::now() - last_progress > std::chrono::seconds(2)) {
      last_progress = std::chrono::steady_clock::now();
      spdlog::info("progress: {:.0f}% ({} events)",
                   100.0 * static_cast<double>(t) / static_cast<double>(scene.duration_us), events);
    }
  }
  for (auto& writer : writers) writer->close();
  ground_truth.close();
  int frames = 0;
  if (frames_hz > 0) {
    // The frames an APS would take at frames_hz, pixel-aligned with the events (ECD layout).
    EcdFrameWriter frame_writer(out_dir);
    std::vector<std::uint8_t> grey;
    const double period_us = 1e6 / frames_hz;
    for (; static_cast<double>(frames) * period_us <= static_cast<double>(scene.duration_us); ++frames) {
      const auto t = static_cast<Timestamp>(std::llround(static_cast<double>(frames) * period_us));
      simulator.render_frame(t, grey, aps);
      frame_writer.write(t, cv::Mat(scene.sensor.height, scene.sensor.width, CV_8UC1, grey.data()));
    }
    frame_writer.close();
    written.push_back(frame_writer.list_path());
  }

  const double seconds = static_cast<double>(scene.duration_us) * 1e-6;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const SimulatorCounters& c = simulator.counters();
  std::printf("evldt-sim summary: scene %s, %dx%d, %.3f s, seed %llu\n", scene.name.c_str(), scene.sensor.width,
              scene.sensor.height, seconds, static_cast<unsigned long long>(sim_options.config().seed));
  std::printf(
      "  events           %llu (%.2f Mev/s): %llu signal, %llu noise, %llu lost to the refractory period, %llu to a "
      "full "
      "readout\n",
      static_cast<unsigned long long>(events), static_cast<double>(events) * 1e-6 / seconds,
      static_cast<unsigned long long>(c.signal_events), static_cast<unsigned long long>(c.noise_events),
      static_cast<unsigned long long>(c.refractory_losses), static_cast<unsigned long long>(c.readout_losses));
  std::printf("  rendering        %llu sub-frames in %.2f s wall; %d frames at %g Hz\n",
              static_cast<unsigned long long>(c.sub_frames), wall, frames, frames_hz);
  for (const auto& path : written) std::printf("  wrote            %s\n", path.string().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "evldt-sim: simulate an event camera watching a built-in scene; writes event recordings and the\n"
      "ground-truth line segments (ground_truth.csv: t_us,gt_id,x0,y0,x1,y1) into a directory, and with\n"
      "--frames-hz the scene's grey frames (images.txt, images/)."};
  SimulatorOptions sim_options;
  std::filesystem::path out_dir = "sim-out";
  std::vector<std::string> formats{"evt3", "ecd"};
  Timestamp gt_period_us = 10000;
  double frames_hz = 0;
  ApsModel aps;
  bool quiet = false;
  bool list = false;
  sim_options.add_to(app, /*scene_required=*/true);
  app.add_option("-o,--out-dir", out_dir, "Directory to write into")->capture_default_str();
  app.add_option("--format", formats,
                 "Recording formats to write: evt3 (events.raw), ecd (events.txt), evt2, evt21, dat")
      ->capture_default_str()
      ->check(CLI::IsMember({"ecd", "evt2", "evt3", "evt21", "dat"}));
  app.add_option("--gt-period-us", gt_period_us, "Event time between ground-truth rows")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{100}, Timestamp{10'000'000}));
  app.add_option(
         "--frames-hz", frames_hz,
         "Also write grey frames of the scene at this rate (images.txt and images/, the ECD layout), pixel-aligned "
         "with the events, for evldt-eval --frames-gt (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10000.0));
  app.add_option("--frames-exposure-us", aps.exposure_us,
                 "Exposure of each frame, centred on its time: motion blurs edges as on a real APS (0: an instant)")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{0}, Timestamp{1'000'000}));
  app.add_option("--frames-noise", aps.read_noise,
                 "Read noise added to each frame's pixels, standard deviation in grey levels")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 255.0));
  app.add_flag("--list", list, "List the built-in scenes and exit");
  app.add_flag("-q,--quiet", quiet, "No progress lines");
  return run_main(app, argc, argv, [&] {
    if (!list) return run(sim_options, out_dir, formats, gt_period_us, frames_hz, aps, quiet);
    for (const auto& name : scene_names()) {
      const Scene s = make_scene(name);
      std::printf("%-18s %dx%d  %.2f s  %zu shapes%s\n", name.c_str(), s.sensor.width, s.sensor.height,
                  static_cast<double>(s.duration_us) * 1e-6, s.shapes.size(),
                  name == kDefaultScene ? "  (default)" : "");
    }
    return 0;
  });
}
