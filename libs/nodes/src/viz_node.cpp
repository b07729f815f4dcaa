#include "evldt/nodes/viz_node.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <bit>
#include <chrono>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "evldt/render/status_text.hpp"
#include "evldt/transport/channels.hpp"

namespace evldt {

void VizTotals::print(std::FILE* out, int video_frames, int png_frames) const {
  fmt::print(out, "evldt-viz summary\n");
  fmt::print(out, "  frames    {} drawn, {} in the video, {} PNG snapshots\n", frames, video_frames, png_frames);
  fmt::print(out, "  received  {} batches ({} lost, {} invalid), {} segment lists ({} invalid), {} stats\n",
             events.sequence.received, events.sequence.lost, events.invalid_messages, segment_lists,
             invalid_segment_lists, stats);
}
namespace {

std::span<const std::uint8_t> payload_of(const lcm::ReceiveBuffer* buffer) {
  return {static_cast<const std::uint8_t*>(buffer->data), buffer->data_size};
}

}  // namespace

VizNode::VizNode(lcm::LCM& lcm, VizNodeOptions options)
    : lcm_(lcm), options_(std::move(options)), receiver_(options_.sensor, options_.time_slack_us, [](SensorSize size) {
        return LatticeGeometry::fits(size, default_config_for(size).lattice.block_size);
      }) {
  if (!(options_.render_hz > 0 && options_.render_hz <= 1000))
    throw std::invalid_argument("render rate must be in (0, 1000] Hz");
  if (!lcm_.good()) throw std::runtime_error("LCM is not initialised (bad URL or no multicast route?)");
  subscriptions_.push_back(lcm_.subscribe(events_channel(options_.camera), &VizNode::on_events, this));
  // Drawing and encoding a frame takes milliseconds: queue the batches meanwhile (LCM's default is 30).
  subscriptions_.back()->setQueueCapacity(kEventQueueCapacity);
  subscriptions_.push_back(lcm_.subscribe(lines_channel(options_.camera), &VizNode::on_lines, this));
  subscriptions_.push_back(lcm_.subscribe(whole_lines_channel(options_.camera), &VizNode::on_whole_lines, this));
  subscriptions_.push_back(lcm_.subscribe(std::string(kStatsChannel), &VizNode::on_stats, this));
}

VizNode::~VizNode() {
  for (auto* subscription : subscriptions_) {
    if (subscription) lcm_.unsubscribe(subscription);
  }
}

void VizNode::on_events(const lcm::ReceiveBuffer* buffer, const std::string&) {
  if (!receiver_.receive(payload_of(buffer), batch_)) return;
  if (!lattice_ || receiver_.restarted()) {
    const LatticeParams params = default_config_for(*receiver_.sensor()).lattice;
    lattice_.emplace(params.sensor, params.block_size, params.alpha, /*keep_surface=*/true);
  }
  if (!first_event_us_ || receiver_.restarted())
    first_event_us_ = batch_.empty() ? std::optional<Timestamp>() : batch_.t.front();
  for (std::size_t i = 0; i < batch_.size(); ++i) lattice_->insert(batch_.x[i], batch_.y[i]);
  events_since_frame_ += batch_.size();
}

bool VizNode::decode_list(const lcm::ReceiveBuffer* buffer, std::vector<TrackedLine>& into) {
  // An invalid list is refused whole; the last valid one stays on screen.
  if (decode_message(payload_of(buffer), lines_msg_) != WireError::None || !read_segment_list(lines_msg_, incoming_)) {
    if (std::has_single_bit(++totals_.invalid_segment_lists)) {
      spdlog::warn("refused {} invalid segment list(s)", totals_.invalid_segment_lists);
    }
    return false;
  }
  into.swap(incoming_);
  return true;
}

void VizNode::on_lines(const lcm::ReceiveBuffer* buffer, const std::string&) {
  if (!decode_list(buffer, lines_)) return;
  lines_t_us_ = lines_msg_.t_us;
  ++totals_.segment_lists;
}

void VizNode::on_whole_lines(const lcm::ReceiveBuffer* buffer, const std::string&) {
  if (decode_list(buffer, whole_lines_)) ++totals_.whole_line_lists;
}

void VizNode::on_stats(const lcm::ReceiveBuffer* buffer, const std::string&) {
  // Other cameras' services and our camera service share the channel: keep our lines service's.
  if (decode_message(payload_of(buffer), stats_msg_) != WireError::None || stats_msg_.source != options_.camera) return;
  if (stats_msg_.service == "evldt-lines") {
    stats_ = stats_msg_;
    ++totals_.stats;
  } else if (stats_msg_.service == "evldt-camera") {
    camera_stats_ = stats_msg_;  // a live camera's lag from its sensor
  }
}

void VizNode::render(cv::Mat& canvas) {
  const SensorSize sensor = *receiver_.sensor();
  RenderOptions render = options_.render;
  render.grid_block_size = lattice_->geometry().block_size;
  picture_.draw(sensor, lattice_->surface(), lines_, whole_lines_, render, canvas);
  if (stats_) draw_masked_pixels(sensor, stats_->masked_pixels, options_.render.scale, canvas);
  update_status();
  // Each group of fields wraps to the picture's width.
  int row = 0;
  for (const auto& group : status_) row = put_text_lines(canvas, wrap_fields(group, canvas.cols), row);
  if (options_.show_key_help) put_text_lines(canvas, wrap_fields(layer_key_help(), canvas.cols), row);
}

void VizNode::update_status() {
  status_.clear();
  // Time is since the first event seen (a real recording's clock is its epoch).
  const double since_first_s = first_event_us_ ? static_cast<double>(lines_t_us_ - *first_event_us_) * 1e-6 : 0.0;
  status_.push_back({options_.camera, fmt::format("t={:.3f} s", std::max(0.0, since_first_s)),
                     fmt::format("{:.2f} Mev/s", event_rate_ * 1e-6), fmt::format("{} lines", lines_.size()),
                     fmt::format("{} whole", whole_lines_.size())});
  if (stats_) {
    status_.push_back({fmt::format("detect {:.0f} Hz", stats_->detect_hz),
                       fmt::format("track {:.0f} Hz", stats_->track_hz),
                       fmt::format("latency {:.1f}/{:.1f} ms{}", stats_->latency_median_ms, stats_->latency_p99_ms,
                                   stats_->latency_from_receipt ? " from receipt" : ""),
                       fmt::format("lost {}", stats_->batches_lost), fmt::format("shed {}", stats_->batches_shed),
                       fmt::format("hot pixels {}", stats_->num_masked_pixels)});
  } else {
    status_.push_back({"no statistics from evldt-lines yet"});
  }
  if (camera_stats_ && camera_stats_->sensor_lag_samples > 0) {
    status_.push_back({fmt::format("camera: sensor lag {:.1f}/{:.1f} ms", camera_stats_->sensor_lag_median_ms,
                                   camera_stats_->sensor_lag_p99_ms)});
  }
  const ReceiverCounts counts = receiver_.counts();
  if (counts.sequence.lost || counts.invalid_messages) {
    status_.push_back({fmt::format("viz: {} batches lost", counts.sequence.lost),
                       fmt::format("{} invalid", counts.invalid_messages)});
  }
}

bool VizNode::handle_pending(Clock::time_point deadline) {
  while (Clock::now() < deadline) {
    const int handled = lcm_.handleTimeout(0);
    if (handled < 0) return false;
    if (handled == 0) return true;
  }
  return true;
}

void VizNode::run(const std::atomic<bool>& stop, const FrameHandler& on_frame) {
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / options_.render_hz));
  auto next_frame = Clock::now() + period;
  auto last_rate = Clock::now();
  cv::Mat canvas;
  bool lcm_failed = false;
  while (!stop.load()) {
    auto now = Clock::now();
    if (now >= next_frame) {
      // Everything that has arrived goes into the frame, for at most one period: a frame that takes
      // longer than its period would otherwise let only one message in between frames, and the
      // picture would fall ever further behind the stream.
      if (!handle_pending(now + period)) {
        lcm_failed = true;
        break;
      }
      now = Clock::now();
      next_frame = std::max(next_frame + period, now);
      const double elapsed = std::chrono::duration<double>(now - last_rate).count();
      event_rate_ = static_cast<double>(events_since_frame_) / elapsed;
      events_since_frame_ = 0;
      last_rate = now;
      if (lattice_) {
        render(canvas);
        ++totals_.frames;
        if (!on_frame(canvas)) break;
      }
      continue;
    }
    const auto wait_ms = std::chrono::duration_cast<std::chrono::milliseconds>(next_frame - now).count();
    if (lcm_.handleTimeout(static_cast<int>(std::clamp<long long>(wait_ms, 1, 100))) < 0 && !stop.load()) {
      lcm_failed = true;  // a stop signal interrupting the wait is not a failure
      break;
    }
  }
  if (lcm_failed) {
    spdlog::error("LCM receive failed; stopping");
  } else {
    // What had arrived before the stop is counted in the summary (bounded: stopping stays prompt).
    handle_pending(Clock::now() + kStopDrain);
  }
}

VizTotals VizNode::totals() const {
  VizTotals totals = totals_;
  totals.events = receiver_.counts();
  return totals;
}

}  // namespace evldt
