#include "evldt/nodes/camera_node.hpp"

#include <bit>
#include <chrono>
#include <spdlog/spdlog.h>
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
               "  events            %llu read, %llu published, %llu dropped (%llu off sensor, %llu back in time), %llu clock resets\n"
               "  batches           %llu (%.1f events each), %.2f MB, %.2f bytes/event, %llu publish failures\n"
               "  time              %.3f s of events in %.3f s wall (%.2fx), %.2f Mev/s, %llu loop restarts\n"
               "  pace              furthest behind: %.1f ms, %llu jumps of event time not waited through\n"
               "  decoding          %llu words of reserved or unknown types skipped, %llu trigger events\n",
               source.c_str(), sensor.width, sensor.height, input_error.empty() ? "" : (" -- " + input_error).c_str(),
               static_cast<unsigned long long>(events_read), static_cast<unsigned long long>(events_published),
               static_cast<unsigned long long>(drops.total()), static_cast<unsigned long long>(drops.off_sensor),
               static_cast<unsigned long long>(drops.time_backwards), static_cast<unsigned long long>(drops.clock_resets),
               static_cast<unsigned long long>(batches),
               batches ? static_cast<double>(events_published) / static_cast<double>(batches) : 0.0,
               static_cast<double>(bytes) * 1e-6,
               events_published ? static_cast<double>(bytes) / static_cast<double>(events_published) : 0.0,
               static_cast<unsigned long long>(publish_failures), event_seconds, wall_seconds,
               wall_seconds > 0 ? event_seconds / wall_seconds : 0.0, rate * 1e-6,
               static_cast<unsigned long long>(loops), max_lag_s * 1e3, static_cast<unsigned long long>(skipped_gaps),
               static_cast<unsigned long long>(decoded.skipped_words), static_cast<unsigned long long>(decoded.trigger_events));
  if (live) {
    std::fprintf(out, "  live lag          sensor -> publish: median %.1f ms, p99 %.1f ms beyond the quickest batch (%u batches); wall - sensor clock %.3f s\n"
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

CameraSummary CameraNode::run(const SourceFactory& open_source, const std::atomic<bool>& stop) {
  std::unique_ptr<EventSource> source = open_source();
  CameraSummary summary;
  summary.source = source->name();
  const std::optional<SensorSize> sensor = options_.sensor ? options_.sensor : source->geometry();
  if (!sensor) {
    throw std::runtime_error(source->name() + " has no sensor size in its header: pass --width and --height");
  }
  if (!sensor->valid()) {
    throw std::runtime_error(sensor->range_error());
  }
  summary.sensor = *sensor;
  EventValidator validator(*sensor, options_.time_slack_us);
  EventBatcher batcher(options_.batch_us, options_.max_batch);
  // A live source's events go out as they come: not paced, and each read's last batch at once, not
  // held until an event of a later window arrives.
  const bool live = source->live();
  summary.live = live;
  sensor_lag_ = SensorLag();
  std::uint64_t clock_resets_seen = 0;
  if (live && options_.loop) throw std::invalid_argument("--loop replays a recording; " + source->name() + " cannot be read again");
  Pacer pacer(live ? 0.0 : options_.speed);
  EventBatch chunk, batch;
  first_published_t_.reset();
  Timestamp offset = 0;         // added to event times so every loop continues forward in time
  bool rebase = false;
  const auto started = Clock::now();
  auto last_progress = started;
  spdlog::info("publishing {} ({}x{}) on {} {}", source->name(), sensor->width, sensor->height, channel_,
               live                 ? std::string("as it comes")
               : options_.speed > 0 ? fmt::format("at {}x real time", options_.speed)
                                    : std::string("at full speed"));

  auto last_stats = started;
  std::uint64_t published_at_last_stats = 0;
  const auto stats = [&](bool final) {
    const auto now = Clock::now();
    const double period_s = std::chrono::duration<double>(now - last_stats).count();
    if (options_.stats_hz <= 0 || (!final && period_s < 1.0 / options_.stats_hz)) return;
    DecodeCounts decoded = summary.decoded;
    if (!final) decoded += source->decode_counts();  // at the end, summary.decoded holds them all
    summary.reconnects = source->reconnects();
    publish_stats(summary, decoded, final ? summary.drops : validator.drops(), period_s,
                  summary.events_published - published_at_last_stats);
    last_stats = now;
    published_at_last_stats = summary.events_published;
  };
  const auto publish_ready = [&](bool flush) {
    while (!stop.load() && batcher.pop(batch, flush)) {
      summary.max_lag_s = std::max(summary.max_lag_s, pacer.wait_until(batch.t.back(), stop));
      publish(batch, summary);
      if (live) {
        if (validator.drops().clock_resets != clock_resets_seen) {  // the camera restarted: its clock began afresh
          clock_resets_seen = validator.drops().clock_resets;
          sensor_lag_.restart();
        }
        sensor_lag_.published(batch.t.back(), header_.utime);
      }
      stats(false);
    }
  };
  try {
    while (!stop.load()) {
      if (!source->read(chunk)) {
        if (!options_.loop) break;
        summary.decoded += source->decode_counts();
        source = open_source();
        ++summary.loops;
        rebase = true;
        continue;
      }
      summary.events_read += chunk.size();
      if (chunk.empty()) continue;
      if (rebase) {
        offset = validator.newest_time() + options_.batch_us - chunk.t.front();
        rebase = false;
      }
      if (offset != 0) {
        for (Timestamp& t : chunk.t) t += offset;
      }
      validator.filter(chunk);
      if (chunk.empty()) continue;
      batcher.push(std::move(chunk));  // chunk gets the storage of a consumed one back
      publish_ready(live);
      if (options_.progress_period_s > 0 &&
          Clock::now() - last_progress > std::chrono::duration<double>(options_.progress_period_s)) {
        last_progress = Clock::now();
        spdlog::info("{:.0f}% of {}: {} events in {} batches, {:.2f} s of event time", 100.0 * source->progress(),
                     source->name(), summary.events_published, summary.batches,
                     summary.event_seconds);
      }
    }
  } catch (const FormatError& error) {
    spdlog::error("{} (every event before it was published)", error.what());
    summary.input_error = error.what();
  }
  publish_ready(true);
  summary.decoded += source->decode_counts();
  summary.drops = validator.drops();
  summary.skipped_gaps = pacer.skipped_gaps();
  summary.sensor_lag = sensor_lag_.run_summary();
  summary.sensor_clock_offset_s = sensor_lag_.clock_offset_s();
  summary.reconnects = source->reconnects();
  summary.wall_seconds = std::chrono::duration<double>(Clock::now() - started).count();
  stats(true);
  return summary;
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
    if (std::has_single_bit(++summary.publish_failures)) spdlog::warn("{} batch publish(es) failed", summary.publish_failures);
  } else {
    if (!first_published_t_) first_published_t_ = batch.t.front();
    summary.event_seconds = static_cast<double>(batch.t.back() - *first_published_t_) * 1e-6;
    summary.events_published += batch.size();
    summary.bytes += wire_.size();
  }
  ++summary.batches;
}

}  // namespace evldt
