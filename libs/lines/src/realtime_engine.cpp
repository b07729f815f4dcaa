#include "evldt/lines/realtime_engine.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

namespace evldt {

namespace {
// Longest run of events stored under one lock hold, so the loops' snapshots never wait long.
constexpr std::size_t kInsertChunk = 8192;
}  // namespace

RealtimeEngine::RealtimeEngine(const PipelineConfig& config)
    : config_(config),
      filters_(config.filters, config.lattice.sensor),
      lattice_(config.lattice.sensor, config.lattice.block_size, config.lattice.alpha),
      detect_view_(config.lattice.sensor, config.lattice.block_size, config.lattice.alpha),
      track_view_(config.lattice.sensor, config.lattice.block_size, config.lattice.alpha),
      lines_(lattice_.geometry(), config.track.reassociation),
      pool_(config.threads),
      detector_(lattice_.geometry(), config.score, &pool_),
      tracker_(lattice_.geometry(), config.score, config.track, &pool_) {}

RealtimeEngine::~RealtimeEngine() { stop(); }

void RealtimeEngine::start() {
  if (detect_thread_.joinable()) return;
  {
    std::lock_guard lock(lattice_mutex_);
    stopping_ = false;
  }
  detect_thread_ = std::thread([this] {
    loop(detect_view_, detect_wake_at_us_, detect_rounds_, config_.schedule.detect_period_us,
         [this](const ScarfLattice& view, Timestamp now) { detector_.detect(view, lines_, now); });
  });
  track_thread_ = std::thread([this] {
    loop(track_view_, track_wake_at_us_, track_rounds_, config_.schedule.track_period_us,
         [this](const ScarfLattice& view, Timestamp now) { tracker_.track(view, lines_, now); });
  });
}

void RealtimeEngine::stop() {
  {
    std::lock_guard lock(lattice_mutex_);
    stopping_ = true;
  }
  lattice_changed_.notify_all();
  if (detect_thread_.joinable()) detect_thread_.join();
  if (track_thread_.joinable()) track_thread_.join();
}

void RealtimeEngine::process(const EventBatch& input) {
  if (input.empty()) return;
  const EventBatch* stored = &input;
  if (!filters_.empty()) {
    std::lock_guard lock(filter_mutex_);
    filters_.filter(input, filtered_);
    stored = &filtered_;
  }
  const EventBatch& batch = *stored;
  const std::size_t n = batch.size();
  // Chunks of the stored events; the last (or only, when the filters dropped all) also takes in the
  // input's time, since events the filters dropped still move event time on.
  std::size_t begin = 0;
  do {
    const std::size_t end = std::min(n, begin + kInsertChunk);
    bool wake = false;
    {
      std::lock_guard lock(lattice_mutex_);
      if (end > begin) {
        lattice_.insert(std::span(batch.x).subspan(begin, end - begin), std::span(batch.y).subspan(begin, end - begin));
        events_stored_ += end - begin;
        latest_event_us_ = std::max(latest_event_us_, batch.t[end - 1]);
      }
      if (end == n) note_input(input);
      wake = latest_event_us_ >= std::min(detect_wake_at_us_, track_wake_at_us_);
    }
    if (wake) lattice_changed_.notify_all();
    begin = end;
  } while (begin < n);
}

void RealtimeEngine::note_input(const EventBatch& input) {
  events_received_ += input.size();
  latest_event_us_ = std::max(latest_event_us_, input.t.back());
}

template <typename Round>
void RealtimeEngine::loop(ScarfLattice& view, Timestamp& wake_at_us, std::atomic<std::uint64_t>& rounds,
                          Timestamp period_us, Round round) {
  std::uint64_t seen = 0;
  Timestamp next_due = std::numeric_limits<Timestamp>::min();
  const auto wall_period = std::chrono::microseconds(period_us);
  for (;;) {
    Timestamp now = 0;
    {
      std::unique_lock lock(lattice_mutex_);
      // A round is due once a period of event time has come in since the last one (the
      // deterministic schedule; more rounds would repeat work the storage thread needs the CPU
      // for). Without new input, a round would repeat the last one.
      const auto due = [&] { return stopping_ || (events_received_ != seen && latest_event_us_ >= next_due); };
      wake_at_us = next_due;
      if (!lattice_changed_.wait_for(lock, wall_period, due)) {
        // A period of wall time without a period of event time (a sparse or ending stream): run
        // on whatever is new, so the last events are never left waiting.
        wake_at_us = std::numeric_limits<Timestamp>::min();
        lattice_changed_.wait(lock, [&] { return stopping_ || events_received_ != seen; });
      }
      wake_at_us = std::numeric_limits<Timestamp>::max();  // busy with a round: nothing to wake
      if (stopping_) return;
      view.copy_state_from(lattice_);
      seen = events_received_;
      now = latest_event_us_;
    }
    next_due = now + period_us;
    {
      std::lock_guard lock(lines_mutex_);
      round(view, now);
      lines_time_us_ = std::max(lines_time_us_, now);
    }
    rounds.fetch_add(1, std::memory_order_relaxed);
  }
}

Timestamp RealtimeEngine::snapshot(std::vector<TrackedLine>& out) const {
  std::lock_guard lock(lines_mutex_);
  out.assign(lines_.lines().begin(), lines_.lines().end());
  return lines_time_us_;
}

std::vector<std::uint32_t> RealtimeEngine::masked_pixels() const {
  std::lock_guard lock(filter_mutex_);
  const auto masked = filters_.masked_pixels();
  return {masked.begin(), masked.end()};
}

EngineCounters RealtimeEngine::counters() const {
  EngineCounters c;
  {
    std::lock_guard lock(filter_mutex_);
    c.filtered = filters_.counts();
  }
  {
    std::lock_guard lock(lattice_mutex_);
    c.events = events_stored_;
    c.events_received = events_received_;
    c.latest_event_us = latest_event_us_;
  }
  {
    std::lock_guard lock(lines_mutex_);
    c.lines_created = lines_.created();
  }
  c.detect_rounds = detect_rounds_.load(std::memory_order_relaxed);
  c.track_rounds = track_rounds_.load(std::memory_order_relaxed);
  return c;
}

void RealtimeEngine::set_first_line_id(std::uint64_t first) {
  std::lock_guard lock(lines_mutex_);
  lines_.set_first_id(first);
}

}  // namespace evldt
