#include "evldt/app/source_options.hpp"

#include <stdexcept>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/sources/live_bytes.hpp"

namespace evldt {

void SourceOptions::add_to(CLI::App& app) {
  app.add_option(
         "input", recording_,
         "Recording: Prophesee RAW (EVT 2.0/2.1/3.0) or .dat, ECD events.txt, a ROS 1 or 2 bag (.bag, .db3, .mcap),\n"
         "AEDAT 2.0/3.1/4.0, Event Stream .es, HDF5 (DSEC, MVSEC, Metavision), or an lcm-log of event batches;\n"
         "the format and sensor size come from the file. Live: '-' (standard input), tcp://HOST:PORT or\n"
         "unix:///PATH: a stream of a RAW file (format from its header, else --format), or with --format aedat4\n"
         "DV's AEDAT 4.0 network output")
      ->check([](const std::string& input) -> std::string {
        if (input == "-" || input.starts_with("tcp://") || input.starts_with("unix://")) return {};
        return CLI::ExistingFile(input);
      });
  app.add_option("--follow", followed_,
                 "Recording that a recorder is still writing (RAW, dat, ECD text, AEDAT 2.0/3.1, .es): events go out "
                 "as it grows")
      ->check(CLI::ExistingFile);
  app.add_option("--follow-idle-s", follow_idle_s_, "--follow ends once the file has not grown for this long")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.01, 86400.0));
  app.add_flag(
      "--reconnect", reconnect_,
      "tcp:// and unix://: connect again when the server closes the stream, cuts it or cannot be reached (waits 0.1 s\n"
      "doubling up to 2 s; counted); the run then ends only on SIGINT/SIGTERM");
  app.add_option("--format", format_,
                 "Recording format when the name or header does not tell: ecd, evt2, evt3, evt21, dat; aedat4: DV's\n"
                 "network stream on tcp:// or unix://")
      ->check(CLI::IsMember({"ecd", "evt2", "evt3", "evt21", "dat", "aedat4"}));
  app.add_option(
      "--lcm-channel,--topic", lcm_channel_,
      "Event channel of an lcm-log, topic of a bag or MCAP file, or event table of an HDF5 file (default: the\n"
      "first EVENTS_* channel / event topic / of /events, /davis/left/events, /CD/events)");
  app.add_option("--from-video", video_,
                 "Video file or webcam index: events by frame differencing (thresholds: --contrast, --contrast-sigma, "
                 "--refractory-us, --seed)");
  app.add_option("--video-fps", video_fps_, "Frame rate of --from-video where the file does not say (default 30)")
      ->check(finite_number() & CLI::Range(0.1, 10000.0));
  simulator_.add_to(app, /*scene_required=*/false);
}

std::unique_ptr<EventSource> SourceOptions::open(Timestamp backwards_slack_us, const std::atomic<bool>& stop) const {
  const int selected =
      int{!recording_.empty()} + int{!followed_.empty()} + int{simulator_.scene_selected()} + int{!video_.empty()};
  if (selected != 1) {
    throw std::invalid_argument(
        "give exactly one source: a recording file, '-', tcp://HOST:PORT, unix:///PATH, --follow FILE, --scene NAME or "
        "--from-video FILE|INDEX");
  }
  if (simulator_.scene_selected()) return open_scene(simulator_.scene(), simulator_.config(), simulator_.scene_name());
  if (!video_.empty()) {
    const SimulatorConfig model = simulator_.config();
    VideoSourceOptions video{video_, {}, video_fps_};
    video.emulator.contrast_on = model.contrast_on;
    video.emulator.contrast_off = model.contrast_off;
    video.emulator.contrast_sigma = model.contrast_sigma;
    video.emulator.refractory_us = model.refractory_us;
    video.emulator.seed = model.seed;
    return open_video(video);
  }
  const bool dv_stream = format_ == "aedat4";
  const bool socket_input = recording_.starts_with("tcp://") || recording_.starts_with("unix://");
  std::optional<EventFormat> format;
  if (!format_.empty() && !dv_stream) format = parse_event_format(format_);
  if (dv_stream && !socket_input)
    throw std::invalid_argument("--format aedat4 is for DV's network stream (tcp:// or unix://)");
  if (reconnect_ && !socket_input) throw std::invalid_argument("--reconnect is for a tcp:// or unix:// input");
  if (!followed_.empty()) {
    return open_stream(
        std::make_unique<FollowedFileBytes>(followed_, std::chrono::duration<double>(follow_idle_s_), stop), format,
        followed_.extension().string());
  }
  if (recording_ == "-") return open_stream(std::make_unique<StdinBytes>(stop), format, "");
  const bool tcp = recording_.starts_with("tcp://"), unix_socket = recording_.starts_with("unix://");
  if (tcp || unix_socket) {
    // One connection's events: DV's AEDAT 4.0 network stream, or a stream in a recording format.
    const auto open_connection = [url = recording_, tcp, dv = dv_stream, format,
                                  &stop]() -> std::unique_ptr<EventSource> {
      std::unique_ptr<ByteSource> bytes;
      if (tcp) {
        bytes = std::make_unique<TcpBytes>(TcpAddress::parse(url), stop);
      } else {
        bytes = std::make_unique<UnixSocketBytes>(url.substr(std::string_view("unix://").size()), stop);
      }
      return dv ? open_dv_stream(std::move(bytes)) : open_stream(std::move(bytes), format, "");
    };
    return reconnect_ ? open_reconnecting(open_connection, stop) : open_connection();
  }
  return open_recording(recording_, format, lcm_channel_, backwards_slack_us);
}

}  // namespace evldt
