#include "evldt/nodes/camera_node.hpp"

#include <spdlog/spdlog.h>
#include <bit>
#include <chrono>
#include <stdexcept>
#include <utility>

#include "evldt/transport/channels.hpp"
#include "evldt/transport/event_batcher.hpp"
#include "evldt/transport/messages.hpp"
#include "evldt/transport/pacer.hpp"

namespace evldt {
namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

void CameraSummary::print(std::FILE* out) const {
  const double rate = wall_seconds > 0 ? static_cast<double>(events_published) / wall_seconds : 0.0;
  std::fprintf(out,
               "evldt-camera summary\n"
               "  source            %s (%dx%d)%s\n"
               "  events            %llu read, %llu published, %llu dropped (%llu off sensor, %llu back in time), %llu "
               "clock resets\n"
               "  batches           %llu (%.1f events each), %.2f MB, %.2f bytes/event, %llu publish failures\n"
               "  time              %.3f s of events in %.3f s wall (%.2fx), %.2f Mev/s, %llu loop restarts\n"
               "  pace              furthest behind: %.1f ms, %llu jumps of event time not waited through\n"
               "  decoding          %llu words of reserved or unknown types skipped, %llu trigger events\n",
               source.c_str(), sensor.width, sensor.height, input_error.empty() ? "" : (" -- " + input_error).c_str(),
               static_cast<unsigned long long>(events_read), static_cast<unsigned long long>(events_published),
               static_cast<unsigned long long>(drops.total()), static_cast<unsigned long long>(drops.off_sensor),
               static_cast<unsigned long long>(drops.time_backwards),
               static_cast<unsigned long long>(drops.clock_resets), static_cast<unsigned long long>(batches),
               batches ? static_cast<double>(events_published) / static_cast<double>(batches) : 0.0,
               static_cast<double>(bytes) * 1e-6,
               events_published ? static_cast<double>(bytes) / static_cast<double>(events_published) : 0.0,
               static_cast<unsigned long long>(publish_failures), event_seconds, wall_seconds,
               wall_seconds > 0 ? event_seconds / wall_seconds : 0.0, rate * 1e-6,
               static_cast<unsigned long long>(loops), max_lag_s * 1e3, static_cast<unsigned long long>(skipped_gaps),
               static_cast<unsigned long long>(decoded.skipped_words),
               static_cast<unsigned long long>(decoded.trigger_events));
  if (live) {
    std::fprintf(out,
                 "  live lag          sensor -> publish: median %.1f ms, p99 %.1f ms beyond the quickest batch (%u "
                 "batches); wall - sensor clock %.3f s\n"
                 "  live input        %llu reconnects\n",
                 sensor_lag.median_ms, sensor_lag.p99_ms, sensor_lag.samples, sensor_clock_offset_s,
                 static_cast<unsigned long long>(reconnects));
  }
}

CameraNode::CameraNode(lcm::LCM& lcm, CameraNodeOptions options, std::int64_t epoch_us)
    : lcm_(lcm), options_(std::move(options)), epoch_us_(epoch_us), channel_(events_channel(options_.camera)) {
  if (options_.batch_us < 1 || options_.max_batch < 1 || !(options_.speed >= 0)) {
    throw std::invalid_argument("batch window, batch size and speed must be positive");
  }
  if (!lcm_.good()) throw std::runtime_error("LCM is not initialised (bad URL or no multicast route?)");
}

/// One run of the node over a source (and its loops): the state run() keeps from read to read.
class CameraNode::Run {
 public:
  Run(CameraNode& node, const SourceFactory& open_source, const std::atomic<bool>& stop)
      : node_(node),
        options_(node.options_),
        open_source_(open_source),
        stop_(stop),
        source_(open_source()),
        validator_(sensor_of(*source_, options_), options_.time_slack_us),
        batcher_(options_.batch_us, options_.max_batch),
        live_(source_->live()),
        pacer_(live_ ? 0.0 : options_.speed) {
    if (live_ && options_.loop)
      throw std::invalid_argument("--loop replays a recording; " + source_->name() + " cannot be read again");
    summary_.source = source_->name();
    summary_.sensor = sensor_of(*source_, options_);
    summary_.live = live_;
    node_.sensor_lag_ = SensorLag();
    node_.first_published_t_.reset();
    spdlog::info("publishing {} ({}x{}) on {} {}", source_->name(), summary_.sensor.width, summary_.sensor.height,
                 node_.channel_,
                 live_                ? std::string("as it comes")
                 : options_.speed > 0 ? fmt::format("at {}x real time", options_.speed)
                                      : std::string("at full speed"));
  }

  CameraSummary run() {
    try {
      while (!stop_.load() && read_and_publish()) {
      }
    } catch (const FormatError& error) {
      spdlog::error("{} (every event before it was published)", error.what());
      summary_.input_error = error.what();
    }
    publish_ready(true);
    summary_.decoded += source_->decode_counts();
    summary_.drops = validator_.drops();
    summary_.skipped_gaps = pacer_.skipped_gaps();
    summary_.sensor_lag = node_.sensor_lag_.run_summary();
    summary_.sensor_clock_offset_s = node_.sensor_lag_.clock_offset_s();
    summary_.reconnects = source_->reconnects();
    summary_.wall_seconds = std::chrono::duration<double>(Clock::now() - started_).count();
    stats(true);
    return summary_;
  }

 private:
  /// The sensor size the options give, else the source's header's; throws without one.
  static SensorSize sensor_of(const EventSource& source, const CameraNodeOptions& options) {
    const std::optional<SensorSize> sensor = options.sensor ? options.sensor : source.geometry();
    if (!sensor)
      throw std::runtime_error(source.name() + " has no sensor size in its header: pass --width and --height");
    if (!sensor->valid()) throw std::runtime_error(sensor->range_error());
    return *sensor;
  }

  /// Reads a chunk of the source and publishes the batches it completes; false once the source
  /// ended (and is not looped).
  bool read_and_publish() {
    if (!source_->read(chunk_)) {
      if (!options_.loop) return false;
      summary_.decoded += source_->decode_counts();
      source_ = open_source_();
      ++summary_.loops;
      rebase_ = true;
      return true;
    }
    summary_.events_read += chunk_.size();
    if (chunk_.empty()) return true;
    if (rebase_) {  // a loop continues forward in time
      offset_ = validator_.newest_time() + options_.batch_us - chunk_.t.front();
      rebase_ = false;
    }
    if (offset_ != 0) {
      for (Timestamp& t : chunk_.t) t += offset_;
    }
    validator_.filter(chunk_);
    if (chunk_.empty()) return true;
    batcher_.push(std::move(chunk_));  // chunk_ gets the storage of a consumed one back
    // A live source's events go out as they come: each read's last batch at once, not held until an
    // event of a later window arrives.
    publish_ready(live_);
    progress();
    return true;
  }

  void publish_ready(bool flush) {
    while (!stop_.load() && batcher_.pop(batch_, flush)) {
      summary_.max_lag_s = std::max(summary_.max_lag_s, pacer_.wait_until(batch_.t.back(), stop_));
      node_.publish(batch_, summary_);
      if (live_) {
        if (validator_.drops().clock_resets != clock_resets_seen_) {  // the camera restarted: its clock began afresh
          clock_resets_seen_ = validator_.drops().clock_resets;
          node_.sensor_lag_.restart();
        }
        node_.sensor_lag_.published(batch_.t.back(), node_.header_.utime);
      }
      stats(false);
    }
  }

  void progress() {
    if (options_.progress_period_s <= 0 ||
        Clock::now() - last_progress_ <= std::chrono::duration<double>(options_.progress_period_s)) {
      return;
    }
    last_progress_ = Clock::now();
    spdlog::info("{:.0f}% of {}: {} events in {} batches, {:.2f} s of event time", 100.0 * source_->progress(),
                 source_->name(), summary_.events_published, summary_.batches, summary_.event_seconds);
  }

  void stats(bool final) {
    const auto now = Clock::now();
    const double period_s = std::chrono::duration<double>(now - last_stats_).count();
    if (options_.stats_hz <= 0 || (!final && period_s < 1.0 / options_.stats_hz)) return;
    DecodeCounts decoded = summary_.decoded;
    if (!final) decoded += source_->decode_counts();  // at the end, summary_.decoded holds them all
    summary_.reconnects = source_->reconnects();
    node_.publish_stats(summary_, decoded, final ? summary_.drops : validator_.drops(), period_s,
                        summary_.events_published - published_at_last_stats_);
    last_stats_ = now;
    published_at_last_stats_ = summary_.events_published;
  }

  CameraNode& node_;
  const CameraNodeOptions& options_;
  const SourceFactory& open_source_;
  const std::atomic<bool>& stop_;
  std::unique_ptr<EventSource> source_;
  CameraSummary summary_;
  EventValidator validator_;
  EventBatcher batcher_;
  bool live_;  // not paced, and each read's batches out at once
  Pacer pacer_;
  EventBatch chunk_, batch_;
  std::uint64_t clock_resets_seen_ = 0;
  Timestamp offset_ = 0;  // added to event times so every loop continues forward in time
  bool rebase_ = false;
  Clock::time_point started_ = Clock::now();
  Clock::time_point last_progress_ = started_;
  Clock::time_point last_stats_ = started_;
  std::uint64_t published_at_last_stats_ = 0;
};

CameraSummary CameraNode::run(const SourceFactory& open_source, const std::atomic<bool>& stop) {
  return Run(*this, open_source, stop).run();
}

void CameraNode::publish_stats(const CameraSummary& summary, const DecodeCounts& decoded, const DropCounts& drops,
                               double period_s, std::uint64_t rate_events) {
  stats_t msg{};
  msg.utime = wall_clock_us();
  msg.epoch = epoch_us_;
  msg.service = "evldt-camera";
  msg.source = options_.camera;
  msg.period_s = period_s;
  msg.events_in = static_cast<std::int64_t>(summary.events_read);
  msg.event_rate = period_s > 0 ? static_cast<double>(rate_events) / period_s : 0.0;
  msg.events_dropped = static_cast<std::int64_t>(drops.total());
  msg.batches_received = static_cast<std::int64_t>(summary.batches);
  msg.batches_lost = static_cast<std::int64_t>(summary.publish_failures);
  msg.words_skipped = static_cast<std::int64_t>(decoded.skipped_words);
  msg.trigger_events = static_cast<std::int64_t>(decoded.trigger_events);
  msg.reconnects = static_cast<std::int64_t>(summary.reconnects);
  const LatencySummary lag = sensor_lag_.take_summary();
  msg.sensor_clock_offset_s = sensor_lag_.clock_offset_s();
  msg.sensor_lag_samples = static_cast<std::int32_t>(lag.samples);
  msg.sensor_lag_median_ms = static_cast<float>(lag.median_ms);
  msg.sensor_lag_p99_ms = static_cast<float>(lag.p99_ms);
  lcm_.publish(std::string(kStatsChannel), &msg);
}

void CameraNode::publish(const EventBatch& batch, CameraSummary& summary) {
  event_batch_t& header = header_;
  header.utime = wall_clock_us();
  header.epoch = epoch_us_;
  header.seq = static_cast<std::int64_t>(summary.batches);
  header.source = options_.camera;
  header.width = static_cast<std::int16_t>(summary.sensor.width);
  header.height = static_cast<std::int16_t>(summary.sensor.height);
  encode_event_batch(header, batch, wire_);
  if (lcm_.publish(channel_, wire_.data(), static_cast<unsigned>(wire_.size())) != 0) {
    // The sequence number still advances: subscribers count the batch as lost.
    if (std::has_single_bit(++summary.publish_failures))
      spdlog::warn("{} batch publish(es) failed", summary.publish_failures);
  } else {
    if (!first_published_t_) first_published_t_ = batch.t.front();
    summary.event_seconds = static_cast<double>(batch.t.back() - *first_published_t_) * 1e-6;
    summary.events_published += batch.size();
    summary.bytes += wire_.size();
  }
  ++summary.batches;
}

}  // namespace evldt
