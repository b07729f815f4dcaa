#include "evldt/pipeline/deterministic_pipeline.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace evldt {

DeterministicPipeline::DeterministicPipeline(const PipelineConfig& config, bool keep_surface)
    : config_(config),
      intake_(config),
      lattice_(config.lattice.sensor, config.lattice.block_size, config.lattice.alpha, keep_surface),
      lines_(lattice_.geometry(), config.track.reassociation, config.track.motion),
      pool_(config.threads),
      detector_(lattice_.geometry(), config.score, &pool_),
      tracker_(lattice_.geometry(), config.score, config.track, &pool_) {
  if (config.schedule.track_period_us <= 0 || config.schedule.detect_period_us <= 0) {
    throw std::invalid_argument("tracking and detection periods must be positive");
  }
}

void DeterministicPipeline::set_output(Timestamp period_us, StepCallback on_step, bool whole_lines) {
  if (period_us < 0) throw std::invalid_argument("output period must not be negative");
  output_period_ = period_us;
  on_step_ = std::move(on_step);
  whole_lines_.reset();
  if (whole_lines) whole_lines_.emplace(config_);
  if (started_) update_next_due();
}

namespace {
// The first multiple of `period` after t (floor division: event times may be negative).
Timestamp first_multiple_after(Timestamp t, Timestamp period) {
  const Timestamp periods = t / period - (t % period < 0 ? 1 : 0);
  return (periods + 1) * period;
}
}  // namespace

void DeterministicPipeline::start(Timestamp t0) {
  // Every schedule runs on multiples of its period, so an output step is taken right after the
  // rounds of its time and falls on the grid ground truth is sampled on.
  started_ = true;
  next_track_ = first_multiple_after(t0, config_.schedule.track_period_us);
  next_detect_ = first_multiple_after(t0, config_.schedule.detect_period_us);
  if (output_period_ > 0) next_output_ = first_multiple_after(t0, output_period_);
  update_next_due();
}

void DeterministicPipeline::update_next_due() {
  next_due_ = std::min(next_track_, next_detect_);
  if (output_period_ > 0) next_due_ = std::min(next_due_, next_output_);
}

void DeterministicPipeline::process(const EventBatch& batch, int copies) {
  if (batch.empty()) return;
  start_or_restart(batch);
  store(intake_.prepare(batch), copies);
  finish_batch(batch);
}

void DeterministicPipeline::filter(const EventBatch& batch, EventBatch& filtered) { intake_.filter(batch, filtered); }

void DeterministicPipeline::process_filtered(const EventBatch& batch, const EventBatch& filtered, int copies) {
  if (batch.empty()) return;
  start_or_restart(batch);
  store(intake_.rectify(filtered), copies);
  finish_batch(batch);
}

void DeterministicPipeline::start_or_restart(const EventBatch& batch) {
  // The schedule follows the input's clock: events the filters drop still move event time on.
  if (!started_) {
    start(batch.t[0]);
  } else if (batch.t[0] < next_due_ - kClockStepBackUs) {
    ++counters_.clock_restarts;
    start(batch.t[0]);
  }
}

void DeterministicPipeline::finish_batch(const EventBatch& batch) {
  counters_.off_rectified = intake_.off_rectified();
  // Rounds due up to the batch's last event: every stored event is older than them (store() ran
  // each round due at or before a stored event's time before storing it).
  if (batch.t.back() >= next_due_) run_rounds_until(batch.t.back());
}

void DeterministicPipeline::store(const EventBatch& batch, int copies) {
  const std::size_t n = batch.size();
  const Timestamp* ts = batch.t.data();
  const std::uint16_t* xs = batch.x.data();
  const std::uint16_t* ys = batch.y.data();
  std::size_t i = 0;
  while (i < n) {
    if (ts[i] >= next_due_) run_rounds_until(ts[i]);
    // The run of events before the next round, stored in one call.
    std::size_t end = i + 1;
    while (end < n && ts[end] < next_due_) ++end;
    lattice_.insert(std::span(xs + i, end - i), std::span(ys + i, end - i), copies);
    i = end;
  }
  counters_.events += n;
}

void DeterministicPipeline::run_rounds_until(Timestamp t) {
  const Timestamp catch_up_limit = config_.schedule.max_catch_up_rounds * config_.schedule.track_period_us;
  while (next_due_ <= t) {
    if (t - next_due_ > catch_up_limit) {
      skip_gap(t - catch_up_limit);
      continue;
    }
    const Timestamp now = next_due_;
    // Track before detecting, so detection sees this round's ownership and suppression.
    if (next_track_ == now) {
      tracker_.track(lattice_, lines_, now);
      next_track_ += config_.schedule.track_period_us;
      ++counters_.track_rounds;
    }
    if (next_detect_ == now) {
      detector_.detect(lattice_, lines_, now);
      next_detect_ += config_.schedule.detect_period_us;
      ++counters_.detect_rounds;
    }
    if (output_period_ > 0 && next_output_ == now) {
      const std::span<const TrackedLine> whole =
          whole_lines_ ? whole_lines_->step(now, lines_.lines(), &lattice_) : std::span<const TrackedLine>{};
      if (on_step_) on_step_({now, lines_, whole, lattice_});
      next_output_ += output_period_;
    }
    update_next_due();
  }
}

void DeterministicPipeline::skip_gap(Timestamp resume_from) {
  // Move every schedule to its first grid time >= resume_from; nothing changed in the lattice meanwhile.
  auto skip = [&](Timestamp& next, Timestamp period, bool counted) {
    if (next >= resume_from) return;
    const Timestamp rounds = (resume_from - next + period - 1) / period;
    next += rounds * period;
    if (counted) counters_.skipped_rounds += static_cast<std::uint64_t>(rounds);
  };
  skip(next_track_, config_.schedule.track_period_us, true);
  skip(next_detect_, config_.schedule.detect_period_us, true);
  if (output_period_ > 0) skip(next_output_, output_period_, false);
  update_next_due();
}

}  // namespace evldt
