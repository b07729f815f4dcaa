#include "evldt/nodes/lines_node.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "evldt/pipeline/thread_name.hpp"
#include "evldt/transport/channels.hpp"

namespace evldt {

void LinesNodeTotals::print(std::FILE* out, const LinesNodeOptions& options) const {
  const SequenceCounts& sequence = receiver.sequence;
  fmt::print(out, "evldt-lines summary\n");
  fmt::print(out,
             "  batches   {} received, {} lost (sequence gaps), {} late ({} resyncs), {} invalid messages, {} camera "
             "restarts\n",
             sequence.received, sequence.lost, sequence.late, sequence.resyncs, receiver.invalid_messages,
             engine_restarts);
  fmt::print(out, "  shed      {} events, not stored: {} batches shed whole, {} thinned (latency budget {:.0f} ms)\n",
             receiver.events_shed, receiver.batches_shed, receiver.batches_thinned, options.max_latency_ms);
  fmt::print(
      out,
      "  events    {} received, {} stored, {} dropped as invalid ({} off sensor, {} back in time), {} clock resets\n",
      events_received, events_stored, receiver.drops.total(), receiver.drops.off_sensor, receiver.drops.time_backwards,
      receiver.drops.clock_resets);
  fmt::print(out, "  filters   dropped {} hot-pixel, {} background-activity, {} refractory, {} anti-flicker\n",
             filtered.hot_pixel, filtered.background_activity, filtered.refractory, filtered.anti_flicker);
  if (events_off_rectified > 0) {  // with a calibration
    fmt::print(out, "  calibration  {} events left out, their pixel sees beyond the rectified image\n",
               events_off_rectified);
  }
  fmt::print(out, "  loops     {} detection rounds ({} while shedding, without the bend test), {} tracking rounds\n",
             detect_rounds, detect_rounds_without_bend_test, track_rounds);
  fmt::print(
      out,
      "  output    {} lines created, {} segment lists published, {} whole-line lists ({} at {} Hz while shedding)\n",
      lines_created, lists_published, whole_lists_published, whole_lists_while_shedding, options.whole_lines_loaded_hz);
  // A replayed log keeps the recording's publish stamps: measured from them, nothing late would read as lag.
  const bool from_receipt = latency_from_receipt > 0;
  fmt::print(
      out,
      "  latency   batch {} -> segment list: median {:.1f} ms, p99 {:.1f} ms ({} batches); settled, from 1 s after\n",
      from_receipt ? "receipt" : "publish", latency.median_ms, latency.p99_ms, latency.samples);
  fmt::print(out, "            the first batch: median {:.1f} ms, p99 {:.1f} ms ({} batches)\n",
             settled_latency.median_ms, settled_latency.p99_ms, settled_latency.samples);
  if (from_receipt) {
    fmt::print(
        out,
        "            measured from receipt for {} batches: their publish stamps are {:.1f} ms {} this host's clock\n"
        "            (a log replayed by lcm-logplayer keeps the recording's, or the camera host's clock is set "
        "apart)\n",
        latency_from_receipt, std::abs(static_cast<double>(publish_clock_offset_us.value_or(0))) * 1e-3,
        publish_clock_offset_us.value_or(0) >= 0 ? "behind" : "ahead of");
  }
}

LinesNode::LinesNode(lcm::LCM& lcm, LinesNodeOptions options, std::int64_t epoch_us)
    : lcm_(lcm),
      options_(std::move(options)),
      ingest_(options_, static_cast<std::uint64_t>(epoch_us)),
      whole_lines_(options_.whole_lines ? std::optional<WholeLinePublisher>(std::in_place, lcm, options_, epoch_us,
                                                                            static_cast<std::uint64_t>(epoch_us))
                                        : std::nullopt),
      segments_(lcm, options_, epoch_us, ingest_, whole_lines_ ? &*whole_lines_ : nullptr),
      statistics_(lcm, options_, epoch_us),
      camera_info_(lcm, options_, epoch_us) {
  if (!(options_.publish_hz > 0 && options_.publish_hz <= 10000) ||
      !(options_.stats_hz > 0 && options_.stats_hz <= 100) ||
      !(options_.whole_lines_hz > 0 && options_.whole_lines_hz <= 10000) ||
      !(options_.whole_lines_loaded_hz > 0 && options_.whole_lines_loaded_hz <= 10000)) {
    throw std::invalid_argument(
        "publish and whole-line rates must be in (0, 10000] Hz and the stats rate in (0, 100] Hz");
  }
  if (!lcm_.good()) throw std::runtime_error("LCM is not initialised (bad URL or no multicast route?)");
  const std::vector<pid_t> threads_before = process_thread_ids();
  subscription_ = lcm_.subscribe(events_channel(options_.camera), &LinesNode::on_events, this);
  if (!subscription_) throw std::runtime_error("cannot subscribe to " + events_channel(options_.camera));
  make_socket_readers_realtime(threads_before);
  // LCM queues 30 messages per subscription by default and drops beyond; a stall of a few ms at
  // kHz batch rates would lose batches.
  subscription_->setQueueCapacity(kEventQueueCapacity);
}

void LinesNode::make_socket_readers_realtime(const std::vector<pid_t>& threads_before) {
  // LCM's udpm provider starts a thread at the first subscription that reads the socket into
  // memory: if it falls behind by what the socket buffer holds (some 40 ms of a 1280x720 stream at
  // 20 Mev/s), batches are lost. Among busy threads of equal priority it did, at the start of a
  // stream (measured at x1: 0-48 batches lost in each of six starts; none in eight as real-time).
  // (memq:// starts none; a ThreadSanitizer build starts its own thread with LCM's.)
  int raised = 0, refused = 0;
  for (const pid_t tid : process_thread_ids()) {
    if (std::ranges::find(threads_before, tid) != threads_before.end()) continue;
    (run_thread_realtime(tid) ? raised : refused) += 1;
  }
  if (refused > 0) {
    spdlog::info("LCM's socket reader runs at normal priority: real-time needs CAP_SYS_NICE (README, real time)");
  } else if (raised > 0) {
    spdlog::debug("LCM's socket reader runs real-time ({} thread(s))", raised);
  }
}

LinesNode::~LinesNode() {
  if (subscription_) lcm_.unsubscribe(subscription_);
  ingest_.stop_engine();
}

void LinesNode::on_events(const lcm::ReceiveBuffer* buffer, const std::string&) {
  // Only queued here (waiting while the queue is full), so that LCM's own queue stays short.
  ingest_.queue(std::span(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size), buffer->recv_utime,
                *stop_);
}

void LinesNode::run(const std::atomic<bool>& stop) {
  stop_ = &stop;
  // Started by this thread, the store thread shares its priority (raised above the rounds').
  std::thread storer([&] { ingest_.store_loop(stop); });
  std::thread publisher([&] { publish_loop(stop); });
  std::thread whole_lines;
  if (whole_lines_) whole_lines = std::thread([&] { whole_lines_->loop(stop); });
  while (!stop.load()) {
    if (lcm_.handleTimeout(100) < 0 && !stop.load()) {
      spdlog::error("LCM receive failed; stopping");  // a stop signal interrupting the wait is not a failure
      break;
    }
  }
  storer.join();
  publisher.join();
  if (whole_lines.joinable()) whole_lines.join();
  ingest_.stop_engine();
}

void LinesNode::publish_loop(const std::atomic<bool>& stop) {
  using Clock = std::chrono::steady_clock;
  name_this_thread("evldt-publish");
  run_this_thread_as_round();
  // A list goes out once a round has changed the lines, at most one per publish period; an
  // unchanged one again after a second (a heartbeat, so a subscriber sees the service live).
  constexpr auto kHeartbeat = std::chrono::seconds(1);
  constexpr auto kLongestWait = std::chrono::milliseconds(100);  // the stop flag is checked this often
  constexpr auto kCameraInfoPeriod =
      std::chrono::milliseconds(250);  // with a calibration: a subscriber waits no longer
  const auto publish_period = period_of(options_.publish_hz);
  const auto stats_period = period_of(options_.stats_hz);
  auto next_publish = Clock::now();
  auto last_list = next_publish;
  auto last_stats = next_publish;
  auto last_log = next_publish;
  auto last_camera_info = next_publish - kCameraInfoPeriod;
  while (!stop.load()) {
    auto now = Clock::now();
    if (now - last_camera_info >= kCameraInfoPeriod) {
      if (const auto engine = ingest_.engine()) camera_info_.publish(*engine);
      last_camera_info = now;
    }
    if (now >= next_publish && segments_.publish(now - last_list >= kHeartbeat)) {
      last_list = now;
      next_publish = now + publish_period;
    }
    if (now - last_stats >= stats_period) {
      const LatencySummary latency = ingest_.take_latency_summary();
      const auto engine = ingest_.engine();
      statistics_.publish(totals(), latency, segments_.live_lines(), engine.get(),
                          std::chrono::duration<double>(now - last_stats).count());
      last_stats = now;
    }
    if (options_.log_period_s > 0 && now - last_log >= std::chrono::duration<double>(options_.log_period_s)) {
      last_log = now;
      statistics_.log(totals());
    }
    now = Clock::now();
    const auto engine = ingest_.engine();
    const auto next_stats = std::min(last_stats + stats_period, now + kLongestWait);
    const auto wake = std::min(next_stats, last_list + kHeartbeat);
    if (!engine) {  // nothing received yet: no list (nor heartbeat) to publish before an engine starts
      ingest_.wait_for_engine(next_stats);
    } else if (now < next_publish) {
      std::this_thread::sleep_until(std::min(next_publish, wake));
    } else {
      segments_.wait_for_round(engine, wake);
    }
  }
}

LinesNodeTotals LinesNode::totals() const {
  LinesNodeTotals totals;
  ingest_.add_to(totals);
  totals.lists_published = segments_.published();
  if (whole_lines_) {
    totals.whole_lists_published = whole_lines_->published();
    totals.whole_lists_while_shedding = whole_lines_->published_while_shedding();
  }
  return totals;
}

}  // namespace evldt
