#include "evldt/pipeline/realtime_engine.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <stdexcept>

#include "evldt/pipeline/thread_name.hpp"

namespace evldt {

namespace {
// Longest run of events stored under one lock hold, so the loops' snapshots never wait long.
constexpr std::size_t kInsertChunk = 8192;
// Batches up to this size (an LCM datagram holds 7000 events) filter without growing a buffer.
constexpr std::size_t kPreparedBatch = std::size_t{1} << 16;
}  // namespace

RealtimeEngine::RealtimeEngine(const PipelineConfig& config)
    : config_(config),
      intake_(config, kPreparedBatch),
      lattice_(config.lattice.sensor, config.lattice.block_size, config.lattice.alpha),
      detect_{ScarfLattice(config.lattice.sensor, config.lattice.block_size, config.lattice.alpha)},
      track_{ScarfLattice(config.lattice.sensor, config.lattice.block_size, config.lattice.alpha)},
      lines_(lattice_.geometry(), config.track.reassociation, config.track.motion),
      pool_(config.threads),
      detector_(lattice_.geometry(), config.score, &pool_),
      tracker_(lattice_.geometry(), config.score, config.track, &pool_) {
  if (config.schedule.shedding_period_factor < 1)
    throw std::invalid_argument("shedding_period_factor must be at least 1");
  if (config.schedule.input_pause_ms < 1) throw std::invalid_argument("input_pause_ms must be at least 1");
}

RealtimeEngine::~RealtimeEngine() { stop(); }

void RealtimeEngine::start() {
  if (detect_thread_.joinable()) return;
  {
    std::lock_guard lock(lattice_mutex_);
    stopping_ = false;
  }
  detect_thread_ = std::thread([this] {
    loop("evldt-detect", detect_, detect_rounds_, config_.schedule.detect_period_us,
         [this](const ScarfLattice& view, Timestamp now, bool shedding) {
           // While shedding, new lines skip the bend test (at x1 on monitor-hd it is a tenth of a
           // core: docs/realtime.md): arcs may be taken for lines until the load eases.
           detector_.detect(view, lines_, now, /*test_bends=*/!shedding);
           if (shedding) detect_rounds_without_bend_test_.fetch_add(1, std::memory_order_relaxed);
         });
  });
  track_thread_ = std::thread([this] {
    loop("evldt-track", track_, track_rounds_, config_.schedule.track_period_us,
         [this](const ScarfLattice& view, Timestamp now, bool /*shedding*/) { tracker_.track(view, lines_, now); });
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

void RealtimeEngine::process(const EventBatch& input, int copies) {
  if (input.empty()) return;
  storing_.store(true, std::memory_order_relaxed);
  const EventBatch* prepared = nullptr;
  {
    std::lock_guard lock(intake_mutex_);
    prepared = &intake_.prepare(input);  // the intake's buffer is the producer's alone
  }
  const EventBatch& batch = *prepared;
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
        lattice_.insert(std::span(batch.x).subspan(begin, end - begin), std::span(batch.y).subspan(begin, end - begin),
                        copies);
        events_stored_ += end - begin;
        latest_event_us_ = std::max(latest_event_us_, batch.t[end - 1]);
      }
      if (end == n) {
        note_input(input);
        wake = hand_over_views();
      }
      wake = wake || latest_event_us_ >= std::min(detect_.wake_at_us, track_.wake_at_us);
    }
    if (wake) lattice_changed_.notify_all();
    begin = end;
  } while (begin < n);
  storing_.store(false, std::memory_order_relaxed);
}

bool RealtimeEngine::hand_over_views() {
  bool handed = false;
  for (LoopState* loop : {&detect_, &track_}) {
    if (!loop->view_wanted) continue;
    take_view(*loop);
    handed = true;
  }
  return handed;
}

void RealtimeEngine::take_view(LoopState& loop) {
  loop.view.copy_state_from(lattice_);
  loop.view_seen = events_received_;
  loop.view_us = latest_event_us_;
  loop.view_wanted = false;
  loop.view_ready = true;
}

void RealtimeEngine::shed(Timestamp until_us) {
  // No round is woken: nothing new was stored, and the next stored batch brings the time with it.
  std::lock_guard lock(lattice_mutex_);
  latest_event_us_ = std::max(latest_event_us_, until_us);
  last_overload_us_ = until_us;
}

void RealtimeEngine::note_overload(Timestamp at_us) {
  std::lock_guard lock(lattice_mutex_);
  last_overload_us_ = std::max(last_overload_us_, at_us);
}

void RealtimeEngine::note_input(const EventBatch& input) {
  events_received_ += input.size();
  latest_event_us_ = std::max(latest_event_us_, input.t.back());
}

template <typename Round>
void RealtimeEngine::loop(const char* thread_name, LoopState& state, std::atomic<std::uint64_t>& rounds,
                          Timestamp period_us, Round round) {
  name_this_thread(thread_name);
  run_this_thread_as_round();
  const auto input_pause = std::chrono::milliseconds(config_.schedule.input_pause_ms);
  std::uint64_t seen = 0;
  Timestamp next_due = std::numeric_limits<Timestamp>::min();
  for (;;) {
    Timestamp now = 0;
    bool shed_lately = false;
    {
      std::unique_lock lock(lattice_mutex_);
      // A round is due once a period of event time has come in since the last one: the rounds
      // follow the events (the deterministic schedule), not the wall clock, so a slow stream costs
      // rounds in proportion to its event time. Only when the input pauses (a sparse or ending
      // stream) does a round run early, on whatever is new, so the last events never wait.
      const auto due = [&] { return stopping_ || (events_received_ != seen && latest_event_us_ >= next_due); };
      state.wake_at_us = next_due;
      bool paused = false;
      while (!due()) {
        if (events_received_ == seen) {
          // Idle (no CPU): woken by any input, which may start a pause that a round must follow.
          state.wake_at_us = std::numeric_limits<Timestamp>::min();
          lattice_changed_.wait(lock, [&] { return stopping_ || events_received_ != seen; });
          state.wake_at_us = next_due;
          continue;
        }
        const std::uint64_t received_before = events_received_;
        if (!lattice_changed_.wait_for(lock, input_pause, due) && events_received_ == received_before) {
          paused = true;
          break;
        }
      }
      state.wake_at_us = std::numeric_limits<Timestamp>::max();  // busy with a round: nothing to wake
      if (stopping_) return;
      // While a batch is being stored, the storing thread copies the lattice into the view when it
      // has stored it: this thread, which may run below storage's priority, then never holds the
      // lattice's lock through a copy while preempted, which stalled storage for milliseconds.
      // Between batches, or when the input paused, the copy is made here at once.
      if (!paused && storing_.load(std::memory_order_relaxed)) {
        state.view_wanted = true;
        lattice_changed_.wait_for(lock, input_pause, [&] { return stopping_ || state.view_ready; });
        if (stopping_) return;
      }
      if (!state.view_ready) take_view(state);
      state.view_ready = false;
      state.view_wanted = false;
      seen = state.view_seen;
      now = state.view_us;
      shed_lately = last_overload_us_ != kNeverShed && now - last_overload_us_ < kSheddingMemoryUs;
    }
    // While batches are being shed the service is past its means: rounds further apart leave the CPU
    // to storage (at x1 on monitor-hd, a third fewer batches shed and F@1% up, docs/realtime.md).
    next_due = now + (shed_lately ? config_.schedule.shedding_period_factor * period_us : period_us);
    {
      std::lock_guard lock(lines_mutex_);
      round(state.view, now, shed_lately);
      lines_time_us_ = std::max(lines_time_us_, now);
      state.last_round_us.store(now, std::memory_order_relaxed);
      lines_version_.fetch_add(1, std::memory_order_release);
    }
    round_done_.notify_all();
    rounds.fetch_add(1, std::memory_order_relaxed);
  }
}

void RealtimeEngine::wait_for_round(std::uint64_t version, std::chrono::steady_clock::time_point deadline) const {
  std::unique_lock lock(lines_mutex_);
  round_done_.wait_until(lock, deadline, [&] { return lines_version_.load(std::memory_order_relaxed) != version; });
}

RealtimeEngine::LinesState RealtimeEngine::snapshot(std::vector<TrackedLine>& out) const {
  std::lock_guard lock(lines_mutex_);
  out.assign(lines_.lines().begin(), lines_.lines().end());
  return {lines_time_us_, lines_version_.load(std::memory_order_relaxed)};
}

void RealtimeEngine::copy_lattice(ScarfLattice& view) const {
  std::lock_guard lock(lattice_mutex_);
  view.copy_state_from(lattice_);
}

std::vector<std::uint32_t> RealtimeEngine::masked_pixels() const {
  std::lock_guard lock(intake_mutex_);
  const auto masked = intake_.masked_pixels();
  return {masked.begin(), masked.end()};
}

EngineCounters RealtimeEngine::counters() const {
  EngineCounters c;
  {
    std::lock_guard lock(intake_mutex_);
    c.filtered = intake_.filter_counts();
    c.off_rectified = intake_.off_rectified();
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
  c.detect_rounds_without_bend_test = detect_rounds_without_bend_test_.load(std::memory_order_relaxed);
  c.track_rounds = track_rounds_.load(std::memory_order_relaxed);
  c.detected_us = detect_.last_round_us.load(std::memory_order_relaxed);
  c.tracked_us = track_.last_round_us.load(std::memory_order_relaxed);
  return c;
}

void RealtimeEngine::set_first_line_id(std::uint64_t first) {
  std::lock_guard lock(lines_mutex_);
  lines_.set_first_id(first);
}

}  // namespace evldt
