// evldt-viz: draws one camera's events (SCARF surface), segments (coloured by status) and whole
// lines from LCM, in a window, a web page (--http) and/or headless into an mp4 and PNG snapshots.

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <opencv2/highgui.hpp>
#include <optional>

#include "evldt/app/lcm_options.hpp"
#include "evldt/app/pipeline_options.hpp"
#include "evldt/nodes/viz_node.hpp"
#include "evldt/render/frame_writer.hpp"
#include "evldt/transport/channels.hpp"
#include "evldt/web/web_view.hpp"

namespace {

/// The status text for a page: a line per group of fields.
std::vector<std::string> joined_status(const std::vector<std::vector<std::string>>& groups) {
  std::vector<std::string> lines;
  for (const auto& group : groups) {
    std::string line;
    for (const std::string& field : group) line += (line.empty() ? "" : "  ") + field;
    lines.push_back(std::move(line));
  }
  return lines;
}

std::vector<evldt::WebLayer> web_layers(const evldt::RenderOptions& render) {
  std::vector<evldt::WebLayer> layers;
  layers.reserve(std::size(evldt::kLayers));
  for (const evldt::Layer& layer : evldt::kLayers) layers.push_back({layer.key, layer.name, render.*(layer.shown)});
  return layers;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace evldt;
  CLI::App app{
      "evldt-viz: show events, segments and whole lines of EVENTS_<CAMERA>, LINES_<CAMERA> and\n"
      "WHOLE_LINES_<CAMERA> (LCM), with the rates of EVLDT_STATS. Colours: cyan whole lines (with ids), below them\n"
      "segments yellow detected, green good track, red bad track. A window unless --headless or no display;\n"
      "--http serves the same picture to browsers (robots without a display); --video and --png-dir record it.\n"
      "Runs until SIGINT/SIGTERM (or q in the window). Keys (window) and buttons (web page) toggle layers:\n"
      "e events, s segments, b bad tracks, w whole lines, i whole-line ids, n segment ids, g block grid."};
  LcmOptions lcm_options;
  VizNodeOptions options;
  std::filesystem::path video, png_dir;
  double png_period_s = 1.0;
  bool headless = false;
  std::string http;
  lcm_options.add_to(app);
  app.add_flag("--headless", headless, "No window (for robots and CI): serve --http and/or write --video, --png-dir");
  app.add_option(
      "--http", http,
      "Serve a live web view on [ADDR:]PORT (e.g. 8080: every interface; 127.0.0.1:8080: this host only; port 0: any "
      "free one, announced); without a display there is then no window");
  app.add_option("--video", video, "Write an mp4 of the frames");
  app.add_option("--png-dir", png_dir, "Write a PNG snapshot every --png-period-s into this directory");
  app.add_option("--png-period-s", png_period_s, "Time between PNG snapshots")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.01, 3600.0));
  app.add_option("--fps", options.render_hz, "Frames drawn per second")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(1.0, 240.0));
  app.add_option("--scale", options.render.scale, "Zoom")->capture_default_str()->check(CLI::Range(1, 8));
  app.add_flag("!--no-whole-lines", options.render.show_whole_lines, "Start without the whole lines (key w)");
  app.add_flag("!--no-ids", options.render.show_whole_line_ids,
               "Start without the whole lines' ids (short numbers in order of first appearance; key i)");
  app.add_flag("--segment-ids", options.render.show_segment_ids, "Write the segments' ids too (key n)");
  app.add_flag("--show-grid", options.render.show_grid, "Draw the lattice's block borders (key g)");
  return run_main(app, argc, argv, [&] {
    const bool display = std::getenv("DISPLAY") || std::getenv("WAYLAND_DISPLAY");
    // OpenCV's window toolkit aborts the process when it finds no display: no window then.
    const bool window = !headless && display;
    if (!window && http.empty() && video.empty() && png_dir.empty()) {
      throw std::invalid_argument(
          headless ? "--headless shows nothing: add --http [ADDR:]PORT, --video FILE and/or --png-dir DIR"
                   : "no display (DISPLAY is not set): add --http [ADDR:]PORT for a web view, or --headless "
                     "with --video FILE and/or --png-dir DIR");
    }
    options.camera = lcm_options.camera();
    options.show_key_help = window;
    std::optional<WebView> web;
    if (!http.empty())
      web.emplace(WebViewOptions{.address = parse_http_address(http), .title = "evldt-viz " + options.camera});
    const auto& stop = stop_on_signals();
    const auto lcm = lcm_options.connect();
    VizNode node(*lcm, options);
    announce_ready("evldt-viz", fmt::format("listening on {}, {} and {} ({}){}", events_channel(options.camera),
                                            lines_channel(options.camera), kStatsChannel, lcm_options.effective_url(),
                                            web ? "; web view at " + web->url() : std::string()));
    std::optional<FrameWriter> video_writer, png_writer;
    const auto png_period = std::chrono::duration<double>(png_period_s);
    auto next_png = std::chrono::steady_clock::now();
    const std::string window_name = "evldt-viz " + lcm_options.camera();
    node.run(stop, [&](const cv::Mat& frame) {
      // Writers open at the first frame: only then is the sensor size known.
      if (!video.empty() && !video_writer)
        video_writer.emplace(video, std::filesystem::path(), options.render_hz, frame.size());
      if (video_writer) video_writer->write(frame);
      if (!png_dir.empty() && std::chrono::steady_clock::now() >= next_png) {
        if (!png_writer) png_writer.emplace(std::filesystem::path(), png_dir, 1.0, frame.size());
        png_writer->write(frame);
        next_png = std::chrono::steady_clock::now() +
                   std::chrono::duration_cast<std::chrono::steady_clock::duration>(png_period);
      }
      if (web) {
        web->publish(frame, joined_status(node.status()), web_layers(node.render_options()));
        for (const char key : web->take_keys()) node.apply_key(key);
      }
      if (window) {
        cv::imshow(window_name, frame);
        const int key = cv::waitKey(1);
        if (key == 'q' || key == 27) return false;
        node.apply_key(key);
      }
      return true;
    });
    node.totals().print(stdout, video_writer ? video_writer->frames() : 0, png_writer ? png_writer->frames() : 0);
    if (web) web->counts().print(stdout);
    return 0;
  });
}
