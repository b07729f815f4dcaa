// evldt-viz: draws one camera's events (SCARF surface) and segments (coloured by status) from LCM,
// in a window or headless into an mp4 and/or PNG snapshots.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <opencv2/highgui.hpp>
#include <optional>
#include <spdlog/spdlog.h>

#include "evldt/app/lcm_options.hpp"
#include "evldt/app/pipeline_options.hpp"
#include "evldt/nodes/viz_node.hpp"
#include "evldt/render/frame_writer.hpp"
#include "evldt/transport/channels.hpp"

int main(int argc, char** argv) {
  using namespace evldt;
  CLI::App app{"evldt-viz: show events and segments of EVENTS_<CAMERA>/LINES_<CAMERA> (LCM), with the rates of\n"
               "EVLDT_STATS. Colours: yellow detected, green good track, red bad track. A window unless --headless;\n"
               "--video and --png-dir record what is drawn. Runs until SIGINT/SIGTERM (or q in the window).\n"
               "In the window, keys toggle what is drawn: e events, s segments, b bad tracks, w whole lines, g block grid,\n"
               "i ids."};
  LcmOptions lcm_options;
  VizNodeOptions options;
  std::filesystem::path video, png_dir;
  double png_period_s = 1.0;
  bool headless = false;
  lcm_options.add_to(app);
  app.add_flag("--headless", headless, "No window (for robots and CI): write --video and/or --png-dir");
  app.add_option("--video", video, "Write an mp4 of the frames");
  app.add_option("--png-dir", png_dir, "Write a PNG snapshot every --png-period-s into this directory");
  app.add_option("--png-period-s", png_period_s, "Time between PNG snapshots")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.01, 3600.0));
  app.add_option("--fps", options.render_hz, "Frames drawn per second")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(1.0, 240.0));
  app.add_option("--scale", options.render.scale, "Zoom")->capture_default_str()->check(CLI::Range(1, 8));
  app.add_flag("--show-ids", options.render.show_ids,
               "Write line ids beside the segments, as short numbers in order of first appearance (key i)");
  app.add_flag("--show-grid", options.render.show_grid, "Draw the lattice's block borders (key g)");
  app.add_flag("--show-whole-lines", options.render.show_whole_lines, "Draw the whole lines of WHOLE_LINES_<CAMERA> (key w)");
  return run_main(app, argc, argv, [&] {
    if (headless && video.empty() && png_dir.empty()) {
      throw std::invalid_argument("--headless draws nothing visible: add --video FILE and/or --png-dir DIR");
    }
    // OpenCV's window toolkit aborts the process when it finds no display: say so first instead.
    if (!headless && !std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY")) {
      throw std::invalid_argument("no display (DISPLAY is not set): run with --headless and --video and/or --png-dir");
    }
    options.camera = lcm_options.camera();
    options.show_key_help = !headless;
    const auto& stop = stop_on_signals();
    const auto lcm = lcm_options.connect();
    VizNode node(*lcm, options);
    announce_ready("evldt-viz", fmt::format("listening on {}, {} and {} ({})", events_channel(options.camera),
                                            lines_channel(options.camera), kStatsChannel, lcm_options.effective_url()));
    std::optional<FrameWriter> video_writer, png_writer;
    const auto png_period = std::chrono::duration<double>(png_period_s);
    auto next_png = std::chrono::steady_clock::now();
    const std::string window = "evldt-viz " + lcm_options.camera();
    node.run(stop, [&](const cv::Mat& frame) {
      // Writers open at the first frame: only then is the sensor size known.
      if (!video.empty() && !video_writer) video_writer.emplace(video, std::filesystem::path(), options.render_hz, frame.size());
      if (video_writer) video_writer->write(frame);
      if (!png_dir.empty() && std::chrono::steady_clock::now() >= next_png) {
        if (!png_writer) png_writer.emplace(std::filesystem::path(), png_dir, 1.0, frame.size());
        png_writer->write(frame);
        next_png = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(png_period);
      }
      if (!headless) {
        cv::imshow(window, frame);
        const int key = cv::waitKey(1);
        if (key == 'q' || key == 27) return false;
        node.apply_key(key);
      }
      return true;
    });
    const VizTotals t = node.totals();
    std::printf("evldt-viz summary\n"
                "  frames    %llu drawn, %d in the video, %d PNG snapshots\n"
                "  received  %llu batches (%llu lost, %llu invalid), %llu segment lists (%llu invalid), %llu stats\n",
                static_cast<unsigned long long>(t.frames), video_writer ? video_writer->frames() : 0,
                png_writer ? png_writer->frames() : 0, static_cast<unsigned long long>(t.events.sequence.received),
                static_cast<unsigned long long>(t.events.sequence.lost),
                static_cast<unsigned long long>(t.events.invalid_messages),
                static_cast<unsigned long long>(t.segment_lists), static_cast<unsigned long long>(t.invalid_segment_lists),
                static_cast<unsigned long long>(t.stats));
    return 0;
  });
}
