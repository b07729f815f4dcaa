#pragma once
// The evldt-viz service without its command line: subscribes to one camera's events, segments and
// the lines service's statistics, keeps a SCARF lattice of the events for the surface image, and
// renders frames at a set rate (surface, segments coloured by status, a status line).

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <string>

#include "evldt/pipeline/pipeline_config.hpp"
#include "evldt/render/line_picture.hpp"
#include "evldt/render/scene_renderer.hpp"
#include "evldt/scarf/scarf_lattice.hpp"
#include "evldt/transport/event_batch_receiver.hpp"

namespace evldt {

struct VizNodeOptions {
  std::string camera = "cam0";
  std::optional<SensorSize> sensor;  ///< unset: the first valid batch's
  double render_hz = 30;
  RenderOptions render{.scale = 2};
  Timestamp time_slack_us = 1000;
  bool show_key_help = false;  ///< a line naming the layer keys (for a window)
};

struct VizTotals {
  ReceiverCounts events;
  std::uint64_t segment_lists = 0;
  std::uint64_t invalid_segment_lists = 0;  ///< of segments and of whole lines
  std::uint64_t whole_line_lists = 0;
  std::uint64_t stats = 0;
  std::uint64_t frames = 0;

  /// The exit summary; the frames the service wrote to a video and as PNG snapshots are its own.
  void print(std::FILE* out, int video_frames, int png_frames) const;
};

class VizNode {
 public:
  /// Takes a rendered frame; returns false to stop.
  using FrameHandler = std::function<bool(const cv::Mat& frame)>;
  VizNode(lcm::LCM& lcm, VizNodeOptions options);
  ~VizNode();
  VizNode(const VizNode&) = delete;
  VizNode& operator=(const VizNode&) = delete;

  /// Receives until `stop` is set (or the handler says stop), handing a frame to `on_frame` render_hz times a second
  /// once the first event batch has arrived; every message received before a frame is due is in it. After a stop,
  /// handles what has already arrived (for at most kStopDrain) so that the totals count it. Everything runs on the
  /// calling thread (window toolkits need it).
  void run(const std::atomic<bool>& stop, const FrameHandler& on_frame);
  /// A key pressed in the window: toggles a layer of kLayers from the next frame on; false for
  /// other keys. Call from the thread that runs the node (the frame handler).
  bool apply_key(int key) { return toggle_layer(options_.render, key); }
  /// What the last frame drew, for a view elsewhere (call from the thread that runs the node).
  [[nodiscard]] const RenderOptions& render_options() const { return options_.render; }
  /// The last frame's status text: groups of fields, each group drawn from a new line.
  [[nodiscard]] const std::vector<std::vector<std::string>>& status() const { return status_; }
  /// Counts so far (call from the thread that runs the node, e.g. in the frame handler, or after run).
  [[nodiscard]] VizTotals totals() const;
  /// Long enough for a viewer that fell behind on a starved host (a ThreadSanitizer build beside two
  /// busy loops had 0.8 s of a stream queued), short of systemd's stop timeout (3 s); a viewer that
  /// kept up stops at once.
  static constexpr std::chrono::milliseconds kStopDrain{2000};

 private:
  using Clock = std::chrono::steady_clock;
  /// Handles messages until none is waiting or the deadline passes; false if LCM failed.
  bool handle_pending(Clock::time_point deadline);
  void on_events(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void on_lines(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void on_whole_lines(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  /// Decodes a segment list into `into`; an invalid one is counted and logged, and `into` kept.
  bool decode_list(const lcm::ReceiveBuffer* buffer, std::vector<TrackedLine>& into);
  void on_stats(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void render(cv::Mat& canvas);
  void update_status();

  lcm::LCM& lcm_;
  VizNodeOptions options_;
  std::vector<lcm::Subscription*> subscriptions_;
  EventBatchReceiver receiver_;
  EventBatch batch_;
  std::optional<ScarfLattice> lattice_;
  std::uint64_t events_since_frame_ = 0;
  double event_rate_ = 0;
  segment_list_t lines_msg_;
  std::vector<TrackedLine> lines_, incoming_;
  std::vector<TrackedLine> whole_lines_;
  LinePicture picture_;
  Timestamp lines_t_us_ = 0;
  std::optional<Timestamp> first_event_us_;  ///< of the stream (since its last restart), for the time shown
  stats_t stats_msg_;
  std::optional<stats_t> stats_;
  std::optional<stats_t> camera_stats_;  ///< our camera service's, for a live source's lag
  std::vector<std::vector<std::string>> status_;
  VizTotals totals_;
};

}  // namespace evldt
