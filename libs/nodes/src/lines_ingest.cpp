#include "evldt/nodes/lines_ingest.hpp"

#include <spdlog/spdlog.h>
#include <bit>
#include <stdexcept>

#include "evldt/pipeline/thread_name.hpp"
#include "evldt/transport/channels.hpp"

namespace evldt {

namespace {
// Batches queued between LCM's handler and the store thread: 80 ms of a 1280x720 stream at 20 Mev/s,
// four times the default latency budget (a fuller queue is shed down by the store thread). Slots
// hold one datagram's payload without growing (16 MiB in all, touched at start).
constexpr std::size_t kQueuedBatches = 256;
constexpr std::size_t kBatchSlotBytes = 64 * 1024;

/// Adds the counts of an engine's life to `sum` (its times are not summed).
void add_counts(EngineCounters& sum, const EngineCounters& engine) {
  sum.events += engine.events;
  sum.events_received += engine.events_received;
  sum.off_rectified += engine.off_rectified;
  sum.filtered += engine.filtered;
  sum.detect_rounds += engine.detect_rounds;
  sum.detect_rounds_without_bend_test += engine.detect_rounds_without_bend_test;
  sum.track_rounds += engine.track_rounds;
  sum.lines_created += engine.lines_created;
}
}  // namespace

LinesIngest::LinesIngest(const LinesNodeOptions& options, std::uint64_t first_line_id)
    : options_(options),
      queue_(kQueuedBatches, kBatchSlotBytes),
      receiver_(options_.sensor, options_.time_slack_us,
                [this](SensorSize size) {
                  // A size the configuration refuses (a calibration of another camera) is refused
                  // here, counted as invalid, not thrown out of the storing thread.
                  try {
                    return LatticeGeometry::fits(size, options_.configure(size).lattice.block_size);
                  } catch (const std::invalid_argument& error) {
                    if (std::has_single_bit(++sizes_refused_)) {  // the 1st, 2nd, 4th, ... time
                      spdlog::warn("a {}x{} sensor refused ({} time(s)): {}", size.width, size.height, sizes_refused_,
                                   error.what());
                    }
                    return false;
                  }
                }),
      budget_(options_.max_latency_ms, 2'000'000, options_.overload),
      next_line_id_(first_line_id) {
  batch_.reserve_touched(1 << 16);
  // Built now when the sensor size is known: building takes tens of ms at 1280x720 (a first touch of
  // 40 MB; up to 200 ms on a virtual machine's fresh memory), and the batches that queue behind it
  // meanwhile would be late, or lost once the socket's buffer fills.
  if (options_.sensor) prebuilt_ = make_engine(*options_.sensor, next_line_id_);
}

LinesIngest::~LinesIngest() { stop_engine(); }

void LinesIngest::stop_engine() {
  if (auto engine = this->engine()) engine->stop();
}

std::shared_ptr<RealtimeEngine> LinesIngest::make_engine(SensorSize sensor, std::uint64_t first_line_id) const {
  auto engine = std::make_shared<RealtimeEngine>(options_.configure(sensor));
  engine->set_first_line_id(first_line_id);
  engine->start();  // its loops wait for events, using no CPU (starting them takes milliseconds)
  return engine;
}

std::shared_ptr<RealtimeEngine> LinesIngest::engine() const {
  std::lock_guard lock(mutex_);
  return engine_;
}

void LinesIngest::wait_for_engine(std::chrono::steady_clock::time_point until) {
  std::unique_lock lock(mutex_);
  engine_started_.wait_until(lock, until, [&] { return engine_ != nullptr; });
}

std::uint64_t LinesIngest::batches_over_budget() const {
  std::lock_guard lock(mutex_);
  return receiver_counts_.batches_shed + receiver_counts_.batches_thinned;
}

LatencyTracker::Included LinesIngest::list_published(Timestamp lattice_us, std::int64_t now_us) {
  std::lock_guard lock(mutex_);
  return latency_.list_published(lattice_us, now_us);
}

LatencySummary LinesIngest::take_latency_summary() {
  std::lock_guard lock(mutex_);
  return latency_.take_summary();
}

void LinesIngest::queue(std::span<const std::uint8_t> payload, std::int64_t received_utime,
                        const std::atomic<bool>& stop) {
  queue_.push(payload, received_utime, stop);
}

void LinesIngest::store_loop(const std::atomic<bool>& stop) {
  name_this_thread("evldt-store");
  while (!stop.load()) {
    const auto payload = queue_.front(std::chrono::milliseconds(100));
    if (!payload) continue;
    store(*payload);
    queue_.pop();
  }
}

void LinesIngest::store(const PayloadQueue::Queued& payload) {
  const bool accepted = receiver_.receive(payload.bytes, batch_, budget_, wall_clock_us());
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
    engine_->process(batch_, RealtimeEngine::stored_copies(receiver_.stride()));
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
    latency_.batch_stored(receiver_.message().seq, receiver_.message().utime, payload.received_utime, batch_.t.back());
  }
}

void LinesIngest::start_engine() {
  // First batch, or the camera restarted or its clock went back: a fresh lattice and lines.
  EngineCounters retired;
  if (engine_) {
    engine_->stop();  // the publisher may still snapshot it meanwhile
    retired = engine_->counters();
    spdlog::warn("camera {} restarted (epoch {}) or its clock went back: lattice and lines begin afresh",
                 options_.camera, receiver_.message().epoch);
  } else {
    const SensorSize sensor = *receiver_.sensor();
    spdlog::info("first batch on {}: {}x{} sensor from '{}'", events_channel(options_.camera), sensor.width,
                 sensor.height, receiver_.message().source);
  }
  // The engine built at start for a configured sensor serves the first batch; a restart needs a fresh one.
  auto engine =
      prebuilt_ ? std::move(prebuilt_) : make_engine(*receiver_.sensor(), next_line_id_ + retired.lines_created);
  prebuilt_.reset();
  spdlog::info("engine: b={}, rounds on {} thread(s)", engine->config().lattice.block_size, engine->config().threads);
  std::lock_guard lock(mutex_);
  if (engine_) ++engine_restarts_;
  engine_ = std::move(engine);
  engine_started_.notify_all();
  if (engine_restarts_ > 0) latency_ = LatencyTracker();  // latency since the camera's (re)start
  next_line_id_ += retired.lines_created;
  add_counts(retired_, retired);
}

void LinesIngest::add_to(LinesNodeTotals& totals) const {
  std::shared_ptr<RealtimeEngine> engine;
  EngineCounters all;
  {
    std::lock_guard lock(mutex_);
    engine = engine_;
    all = retired_;
    totals.receiver = receiver_counts_;
    totals.engine_restarts = engine_restarts_;
    totals.latency = latency_.run_summary();
    totals.settled_latency = latency_.settled_summary();
    totals.latency_from_receipt = latency_.measured_from_receipt();
    totals.publish_clock_offset_us = latency_.publish_clock_offset_us();
  }
  if (engine) add_counts(all, engine->counters());
  totals.events_stored = all.events;
  totals.events_received = all.events_received;
  totals.events_off_rectified = all.off_rectified;
  totals.filtered = all.filtered;
  totals.detect_rounds = all.detect_rounds;
  totals.detect_rounds_without_bend_test = all.detect_rounds_without_bend_test;
  totals.track_rounds = all.track_rounds;
  totals.lines_created = all.lines_created;
}

}  // namespace evldt
