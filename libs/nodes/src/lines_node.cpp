#include "evldt/nodes/lines_node.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <spdlog/spdlog.h>
#include <fmt/core.h>
#include <stdexcept>

#include "evldt/lines/thread_name.hpp"
#include "evldt/transport/channels.hpp"

namespace evldt {

void LinesNodeTotals::print(std::FILE* out, const LinesNodeOptions& options) const {
  const SequenceCounts& sequence = receiver.sequence;
  fmt::print(out, "evldt-lines summary\n");
  fmt::print(out, "  batches   {} received, {} lost (sequence gaps), {} late ({} resyncs), {} invalid messages, {} camera restarts\n",
             sequence.received, sequence.lost, sequence.late, sequence.resyncs, receiver.invalid_messages, engine_restarts);
  fmt::print(out, "  shed      {} events, not stored: {} batches shed whole, {} thinned (latency budget {:.0f} ms)\n",
             receiver.events_shed, receiver.batches_shed, receiver.batches_thinned, options.max_latency_ms);
  fmt::print(out, "  events    {} received, {} stored, {} dropped as invalid ({} off sensor, {} back in time), {} clock resets\n",
             events_received, events_stored, receiver.drops.total(), receiver.drops.off_sensor, receiver.drops.time_backwards,
             receiver.drops.clock_resets);
  fmt::print(out, "  filters   dropped {} hot-pixel, {} background-activity, {} refractory, {} anti-flicker\n", filtered.hot_pixel,
             filtered.background_activity, filtered.refractory, filtered.anti_flicker);
  fmt::print(out, "  loops     {} detection rounds ({} while shedding, without the bend test), {} tracking rounds\n", detect_rounds,
             detect_rounds_without_bend_test, track_rounds);
  fmt::print(out, "  output    {} lines created, {} segment lists published, {} whole-line lists ({} at {} Hz while shedding)\n",
             lines_created, lists_published, whole_lists_published, whole_lists_while_shedding, options.whole_lines_loaded_hz);
  fmt::print(out, "  latency   batch publish -> segment list: median {:.1f} ms, p99 {:.1f} ms ({} batches); settled, from 1 s after\n",
             latency.median_ms, latency.p99_ms, latency.samples);
  fmt::print(out, "            the first batch: median {:.1f} ms, p99 {:.1f} ms ({} batches)\n", settled_latency.median_ms,
             settled_latency.p99_ms, settled_latency.samples);
}
namespace {
// A statistics message lists at most this many masked pixels (16 KiB), whatever a broken sensor does.
constexpr std::size_t kMaxListedMaskedPixels = 4096;

using Clock = std::chrono::steady_clock;

// Whole lines stay at their lower rate until no batch has been shed or thinned for this long.
constexpr std::chrono::seconds kSheddingMemory{1};

// Batches queued between LCM's handler and the store thread: 80 ms of a 1280x720 stream at 20 Mev/s,
// four times the default latency budget (a fuller queue is shed down by the store thread). Slots
// hold one datagram's payload without growing (16 MiB in all, touched at start).
constexpr std::size_t kQueuedBatches = 256;
constexpr std::size_t kBatchSlotBytes = 64 * 1024;

Clock::duration period_of(double hz) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / hz));
}

}  // namespace

LinesNode::LinesNode(lcm::LCM& lcm, LinesNodeOptions options, std::int64_t epoch_us)
    : lcm_(lcm),
      options_(std::move(options)),
      epoch_us_(epoch_us),
      lines_channel_(lines_channel(options_.camera)),
      whole_lines_channel_(whole_lines_channel(options_.camera)),
      queue_(kQueuedBatches, kBatchSlotBytes),
      receiver_(options_.sensor, options_.time_slack_us,
                [this](SensorSize size) {
                  return LatticeGeometry::fits(size, options_.configure(size).lattice.block_size);
                }),
      budget_(options_.max_latency_ms, 2'000'000, options_.overload),
      next_line_id_(static_cast<std::uint64_t>(epoch_us)),
      next_whole_id_(static_cast<std::uint64_t>(epoch_us)) {
  batch_.reserve_touched(1 << 16);
  if (!(options_.publish_hz > 0 && options_.publish_hz <= 10000) || !(options_.stats_hz > 0 && options_.stats_hz <= 100) ||
      !(options_.whole_lines_hz > 0 && options_.whole_lines_hz <= 10000) ||
      !(options_.whole_lines_loaded_hz > 0 && options_.whole_lines_loaded_hz <= 10000)) {
    throw std::invalid_argument("publish and whole-line rates must be in (0, 10000] Hz and the stats rate in (0, 100] Hz");
  }
  if (!lcm_.good()) throw std::runtime_error("LCM is not initialised (bad URL or no multicast route?)");
  const std::vector<pid_t> threads_before = process_thread_ids();
  subscription_ = lcm_.subscribe(events_channel(options_.camera), &LinesNode::on_events, this);
  if (!subscription_) throw std::runtime_error("cannot subscribe to " + events_channel(options_.camera));
  make_socket_readers_realtime(threads_before);
  // LCM queues 30 messages per subscription by default and drops beyond; a stall of a few ms at
  // kHz batch rates would lose batches.
  subscription_->setQueueCapacity(kEventQueueCapacity);
  // Built now when the sensor size is known: building takes tens of ms at 1280x720 (a first touch of
  // 40 MB; up to 200 ms on a virtual machine's fresh memory), and the batches that queue behind it
  // meanwhile would be late, or lost once the socket's buffer fills.
  if (options_.sensor) prebuilt_ = make_engine(*options_.sensor, next_line_id_);
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

std::shared_ptr<RealtimeEngine> LinesNode::make_engine(SensorSize sensor, std::uint64_t first_line_id) const {
  auto engine = std::make_shared<RealtimeEngine>(options_.configure(sensor));
  engine->set_first_line_id(first_line_id);
  engine->start();  // its loops wait for events, using no CPU (starting them takes milliseconds)
  return engine;
}

LinesNode::~LinesNode() {
  if (subscription_) lcm_.unsubscribe(subscription_);
  if (auto engine = this->engine()) engine->stop();
}

std::shared_ptr<RealtimeEngine> LinesNode::engine() const {
  std::lock_guard lock(mutex_);
  return engine_;
}

void LinesNode::on_events(const lcm::ReceiveBuffer* buffer, const std::string&) {
  // Only queued here (waiting while the queue is full), so that LCM's own queue stays short.
  queue_.push(std::span(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size), *stop_);
}

void LinesNode::store_loop(const std::atomic<bool>& stop) {
  name_this_thread("evldt-store");
  while (!stop.load()) {
    const auto payload = queue_.front(std::chrono::milliseconds(100));
    if (!payload) continue;
    store(*payload);
    queue_.pop();
  }
}

void LinesNode::store(std::span<const std::uint8_t> payload) {
  const bool accepted = receiver_.receive(payload, batch_, budget_, wall_clock_us());
  if (accepted && (!engine_ || receiver_.restarted())) {
    start_engine();
    // The batches that queued while the lattice and the rounds were built (tens of ms at
    // 1280x720, more under a sanitizer) are stored: a one-off start, not a service behind.
    budget_.ready_at(wall_clock_us());
  }
  if (accepted && receiver_.shed()) {
    engine_->shed(receiver_.shed_until_us());
    if (std::has_single_bit(receiver_.counts().batches_shed)) {
      spdlog::warn("shed {} batch(es) that came later than the {} ms latency budget (latest queued {:.1f} ms)",
                   receiver_.counts().batches_shed, options_.max_latency_ms,
                   static_cast<double>(budget_.last_queueing_us()) * 1e-3);
    }
  } else if (accepted && !batch_.empty()) {
    engine_->process(batch_);
    if (receiver_.thinned()) {
      engine_->note_overload(batch_.t.back());
      if (std::has_single_bit(receiver_.counts().batches_thinned)) {
        spdlog::warn("thinned {} batch(es) that queued (latest {:.1f} ms): a share of their events stored, evenly",
                     receiver_.counts().batches_thinned, static_cast<double>(budget_.last_queueing_us()) * 1e-3);
      }
    }
  }
  std::lock_guard lock(mutex_);
  receiver_counts_ = receiver_.counts();
  if (accepted && !batch_.empty()) {
    latency_.batch_stored(receiver_.message().seq, receiver_.message().utime, batch_.t.back());
  }
}

void LinesNode::start_engine() {
  // First batch, or the camera restarted or its clock went back: a fresh lattice and lines.
  EngineCounters retired;
  if (engine_) {
    engine_->stop();  // the publisher may still snapshot it meanwhile
    retired = engine_->counters();
    spdlog::warn("camera {} restarted (epoch {}) or its clock went back: lattice and lines begin afresh", options_.camera,
                 receiver_.message().epoch);
  } else {
    const SensorSize sensor = *receiver_.sensor();
    spdlog::info("first batch on {}: {}x{} sensor from '{}'", events_channel(options_.camera), sensor.width,
                 sensor.height, receiver_.message().source);
  }
  // The engine built at start for a configured sensor serves the first batch; a restart needs a fresh one.
  auto engine = prebuilt_ ? std::move(prebuilt_) : make_engine(*receiver_.sensor(), next_line_id_ + retired.lines_created);
  prebuilt_.reset();
  spdlog::info("engine: b={}, rounds on {} thread(s)", engine->config().lattice.block_size, engine->config().threads);
  std::lock_guard lock(mutex_);
  if (engine_) ++engine_restarts_;
  engine_ = std::move(engine);
  engine_started_.notify_all();
  if (engine_restarts_ > 0) latency_ = LatencyTracker();  // latency since the camera's (re)start
  next_line_id_ += retired.lines_created;
  retired_.events += retired.events;
  retired_.events_received += retired.events_received;
  retired_.filtered += retired.filtered;
  retired_.detect_rounds += retired.detect_rounds;
  retired_.detect_rounds_without_bend_test += retired.detect_rounds_without_bend_test;
  retired_.track_rounds += retired.track_rounds;
  retired_.lines_created += retired.lines_created;
}

void LinesNode::run(const std::atomic<bool>& stop) {
  stop_ = &stop;
  // Started by this thread, the store thread shares its priority (raised above the rounds').
  std::thread storer([&] { store_loop(stop); });
  std::thread publisher([&] { publish_loop(stop); });
  std::thread whole_lines;
  if (options_.whole_lines) whole_lines = std::thread([&] { whole_line_loop(stop); });
  while (!stop.load()) {
    if (lcm_.handleTimeout(100) < 0 && !stop.load()) {
      spdlog::error("LCM receive failed; stopping");  // a stop signal interrupting the wait is not a failure
      break;
    }
  }
  storer.join();
  publisher.join();
  if (whole_lines.joinable()) whole_lines.join();
  if (auto engine = this->engine()) engine->stop();
}

void LinesNode::publish_loop(const std::atomic<bool>& stop) {
  name_this_thread("evldt-publish");
  run_this_thread_as_round();
  // A list goes out once a round has changed the lines, at most one per publish period; an
  // unchanged one again after a second (a heartbeat, so a subscriber sees the service live).
  constexpr auto kHeartbeat = std::chrono::seconds(1);
  constexpr auto kLongestWait = std::chrono::milliseconds(100);  // the stop flag is checked this often
  const auto publish_period = period_of(options_.publish_hz);
  const auto stats_period = period_of(options_.stats_hz);
  auto next_publish = Clock::now();
  auto last_list = next_publish;
  auto last_stats = next_publish;
  auto last_log = next_publish;
  while (!stop.load()) {
    auto now = Clock::now();
    if (now >= next_publish && publish_segments(now - last_list >= kHeartbeat)) {
      last_list = now;
      next_publish = now + publish_period;
    }
    if (now - last_stats >= stats_period) {
      publish_stats(std::chrono::duration<double>(now - last_stats).count());
      last_stats = now;
    }
    if (options_.log_period_s > 0 && now - last_log >= std::chrono::duration<double>(options_.log_period_s)) {
      last_log = now;
      const LinesNodeTotals t = totals();
      spdlog::info("{} events stored, {} batches ({} lost, {} shed over the latency budget, {} invalid messages), "
                   "{} lines created, {} lists published, latency {:.1f} / {:.1f} ms (median / p99 of the last "
                   "statistics period)",
                   t.events_stored, t.receiver.sequence.received, t.receiver.sequence.lost, t.receiver.batches_shed,
                   t.receiver.invalid_messages, t.lines_created, t.lists_published, last_latency_.median_ms,
                   last_latency_.p99_ms);
    }
    now = Clock::now();
    const auto engine = this->engine();
    const auto next_stats = std::min(last_stats + stats_period, now + kLongestWait);
    const auto wake = std::min(next_stats, last_list + kHeartbeat);
    if (!engine) {  // nothing received yet: no list (nor heartbeat) to publish before an engine starts
      std::unique_lock lock(mutex_);
      engine_started_.wait_until(lock, next_stats, [&] { return engine_ != nullptr; });
    } else if (now < next_publish) {
      std::this_thread::sleep_until(std::min(next_publish, wake));
    } else {
      engine->wait_for_round(published_engine_ == engine ? published_version_ : 0, wake);
    }
  }
}

bool LinesNode::publish_segments(bool heartbeat) {
  const auto engine = this->engine();
  if (!engine) return false;  // nothing received yet
  const bool same_engine = engine == published_engine_;
  if (same_engine && !heartbeat && engine->lines_version() == published_version_) return false;  // no round since the last list
  const RealtimeEngine::LinesState state = engine->snapshot(lines_);
  published_engine_ = engine;
  published_version_ = state.version;
  const Timestamp lattice_us = state.lattice_us;
  fill_segment_list(lines_, list_msg_);
  const std::int64_t now = wall_clock_us();
  LatencyTracker::Included included;
  {
    std::lock_guard lock(mutex_);
    included = latency_.list_published(lattice_us, now);
  }
  const ListHeader header{now, lattice_us, included.seq, included.utime, engine->geometry().sensor};
  fill_header(header, list_seq_++, list_msg_);
  if (lcm_.publish(lines_channel_, &list_msg_) == 0) lists_published_.fetch_add(1, std::memory_order_relaxed);
  // Whole lines at most at their rate in wall time (up to a publish period early, so at equal
  // rates they go with every segment list) and in event time (up to a tracking period early): a
  // stream replayed slowly costs whole-line steps in proportion to its event time, as it does rounds.
  // While batches are being shed or thinned, at their lower rate: the service is past its means, and
  // the tracking rounds, whose lists the whole lines are built from, need the CPU first.
  const auto now_steady = Clock::now();
  std::uint64_t shed;
  {
    std::lock_guard lock(mutex_);
    shed = receiver_counts_.batches_shed + receiver_counts_.batches_thinned;
  }
  if (shed != shed_seen_) {
    if (options_.whole_lines && (shed_seen_ == 0 || now_steady - last_shed_ >= kSheddingMemory)) {
      spdlog::info("shedding: whole lines at most {} Hz until no batch has been shed or thinned for {} s",
                   options_.whole_lines_loaded_hz, std::chrono::duration<double>(kSheddingMemory).count());
    }
    shed_seen_ = shed;
    last_shed_ = now_steady;
  }
  const bool shedding = shed_seen_ > 0 && now_steady - last_shed_ < kSheddingMemory;
  const double whole_hz = shedding ? std::min(options_.whole_lines_hz, options_.whole_lines_loaded_hz) : options_.whole_lines_hz;
  const Timestamp event_period_us = static_cast<Timestamp>(1e6 / whole_hz) - engine->config().schedule.track_period_us;
  const bool whole_due = now_steady >= next_whole_list_ &&
                         (engine != whole_engine_handed_ || lattice_us < whole_time_handed_ ||
                          lattice_us - whole_time_handed_ >= event_period_us);
  if (options_.whole_lines && whole_due) {
    next_whole_list_ = now_steady + period_of(whole_hz) - period_of(options_.publish_hz);
    whole_engine_handed_ = engine;
    whole_time_handed_ = lattice_us;
    hand_over_whole_step(engine, header, shedding);
  }
  return true;
}

void LinesNode::fill_header(const ListHeader& header, std::int64_t seq, segment_list_t& msg) const {
  msg.utime = header.utime;
  msg.epoch = epoch_us_;
  msg.seq = seq;
  msg.source = options_.camera;
  msg.width = static_cast<std::int16_t>(header.sensor.width);
  msg.height = static_cast<std::int16_t>(header.sensor.height);
  msg.t_us = header.t_us;
  msg.newest_batch_seq = header.newest_batch_seq;
  msg.newest_batch_utime = header.newest_batch_utime;
}

void LinesNode::hand_over_whole_step(const std::shared_ptr<RealtimeEngine>& engine, const ListHeader& header, bool shedding) {
  {
    std::lock_guard lock(whole_mutex_);
    WholeLineStep& step = next_whole_step_;
    step.engine = engine;
    step.lines.assign(lines_.begin(), lines_.end());  // no allocation once as many lines were handed over
    step.header = header;
    step.shedding = shedding;
    whole_step_waiting_ = true;
  }
  whole_step_handed_.notify_one();
}

void LinesNode::whole_line_loop(const std::atomic<bool>& stop) {
  name_this_thread("evldt-whole");
  run_this_thread_as_round();
  constexpr auto kLongestWait = std::chrono::milliseconds(100);  // the stop flag is checked this often
  while (!stop.load()) {
    {
      std::unique_lock lock(whole_mutex_);
      if (!whole_step_handed_.wait_for(lock, kLongestWait, [&] { return whole_step_waiting_; })) continue;
      std::swap(whole_step_, next_whole_step_);  // the newest step; its buffers come back for the next
      whole_step_waiting_ = false;
    }
    publish_whole_lines();
    whole_lists_published_.fetch_add(1, std::memory_order_relaxed);
    if (whole_step_.shedding) whole_lists_while_shedding_.fetch_add(1, std::memory_order_relaxed);
  }
}

void LinesNode::publish_whole_lines() {
  const WholeLineStep& step = whole_step_;
  const RealtimeEngine& engine = *step.engine;
  // A new engine (camera restart, clock back) starts its whole lines afresh; ids go on, never repeated.
  if (step.engine != joined_engine_ || (joiner_ && step.header.t_us < joiner_->last_time())) {
    if (joiner_) next_whole_id_ += joiner_->created();
    joiner_.emplace(engine.config(), next_whole_id_);
    joined_engine_ = step.engine;
    const LatticeParams& lattice = engine.config().lattice;
    whole_view_.emplace(lattice.sensor, lattice.block_size, lattice.alpha);
  }
  engine.copy_lattice(*whole_view_);  // the events gaps are checked against
  fill_segment_list(joiner_->step(step.header.t_us, step.lines, &*whole_view_), whole_msg_);
  fill_header(step.header, whole_seq_++, whole_msg_);  // that of the segment list the step was made of
  lcm_.publish(whole_lines_channel_, &whole_msg_);
}

void LinesNode::publish_stats(double period_s) {
  const LinesNodeTotals now = totals();
  LatencySummary latency;
  {
    std::lock_guard lock(mutex_);
    latency = latency_.take_summary();
  }
  const auto rate = [&](std::uint64_t current, std::uint64_t before) {
    return static_cast<double>(current - before) / period_s;
  };
  stats_t msg{};
  msg.utime = wall_clock_us();
  msg.epoch = epoch_us_;
  msg.service = "evldt-lines";
  msg.source = options_.camera;
  msg.period_s = period_s;
  msg.events_in = static_cast<std::int64_t>(now.events_stored);
  msg.event_rate = rate(now.events_stored, last_stats_.events_stored);
  msg.events_dropped = static_cast<std::int64_t>(now.receiver.drops.total());
  msg.batches_received = static_cast<std::int64_t>(now.receiver.sequence.received);
  msg.batches_lost = static_cast<std::int64_t>(now.receiver.sequence.lost);
  msg.invalid_messages = static_cast<std::int64_t>(now.receiver.invalid_messages);
  msg.detect_hz = rate(now.detect_rounds, last_stats_.detect_rounds);
  msg.track_hz = rate(now.track_rounds, last_stats_.track_rounds);
  msg.live_lines = static_cast<std::int32_t>(lines_.size());
  msg.lists_published = static_cast<std::int64_t>(now.lists_published);
  msg.latency_samples = static_cast<std::int32_t>(latency.samples);
  msg.latency_median_ms = static_cast<float>(latency.median_ms);
  msg.latency_p99_ms = static_cast<float>(latency.p99_ms);
  msg.latency_budget_ms = static_cast<float>(options_.max_latency_ms);
  msg.batches_shed = static_cast<std::int64_t>(now.receiver.batches_shed);
  msg.events_shed = static_cast<std::int64_t>(now.receiver.events_shed);
  msg.filtered_hot_pixel = static_cast<std::int64_t>(now.filtered.hot_pixel);
  msg.filtered_background_activity = static_cast<std::int64_t>(now.filtered.background_activity);
  msg.filtered_refractory = static_cast<std::int64_t>(now.filtered.refractory);
  msg.filtered_anti_flicker = static_cast<std::int64_t>(now.filtered.anti_flicker);
  msg.filters = "none";
  if (const auto engine = this->engine()) {
    msg.filters = format_filter_chain(engine->config().filters.chain);
    std::vector<std::uint32_t> masked = engine->masked_pixels();
    masked.resize(std::min<std::size_t>(masked.size(), kMaxListedMaskedPixels));
    msg.masked_pixels.assign(masked.begin(), masked.end());
  }
  msg.num_masked_pixels = static_cast<std::int32_t>(msg.masked_pixels.size());
  lcm_.publish(std::string(kStatsChannel), &msg);
  last_stats_ = now;
  last_latency_ = latency;
}

LinesNodeTotals LinesNode::totals() const {
  LinesNodeTotals totals;
  std::shared_ptr<RealtimeEngine> engine;
  {
    std::lock_guard lock(mutex_);
    engine = engine_;
    totals.receiver = receiver_counts_;
    totals.engine_restarts = engine_restarts_;
    totals.events_stored = retired_.events;
    totals.events_received = retired_.events_received;
    totals.filtered = retired_.filtered;
    totals.detect_rounds = retired_.detect_rounds;
    totals.detect_rounds_without_bend_test = retired_.detect_rounds_without_bend_test;
    totals.track_rounds = retired_.track_rounds;
    totals.lines_created = retired_.lines_created;
    totals.latency = latency_.run_summary();
    totals.settled_latency = latency_.settled_summary();
  }
  if (engine) {
    const EngineCounters counters = engine->counters();
    totals.events_stored += counters.events;
    totals.events_received += counters.events_received;
    totals.filtered += counters.filtered;
    totals.detect_rounds += counters.detect_rounds;
    totals.detect_rounds_without_bend_test += counters.detect_rounds_without_bend_test;
    totals.track_rounds += counters.track_rounds;
    totals.lines_created += counters.lines_created;
  }
  totals.lists_published = lists_published_.load(std::memory_order_relaxed);
  totals.whole_lists_published = whole_lists_published_.load(std::memory_order_relaxed);
  totals.whole_lists_while_shedding = whole_lists_while_shedding_.load(std::memory_order_relaxed);
  return totals;
}

}  // namespace evldt
