#include "evldt/nodes/line_publishers.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>

#include "evldt/pipeline/thread_name.hpp"
#include "evldt/transport/channels.hpp"
#include "evldt/transport/messages.hpp"

namespace evldt {

namespace {
using Clock = std::chrono::steady_clock;
// Whole lines stay at their lower rate until no batch has been shed or thinned for this long.
constexpr std::chrono::seconds kSheddingMemory{1};
}  // namespace

Clock::duration period_of(double hz) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / hz));
}

void fill_header(const ListHeader& header, std::int64_t epoch_us, const std::string& camera, std::int64_t seq,
                 segment_list_t& msg) {
  msg.utime = header.utime;
  msg.epoch = epoch_us;
  msg.seq = seq;
  msg.source = camera;
  msg.width = static_cast<std::int16_t>(header.sensor.width);
  msg.height = static_cast<std::int16_t>(header.sensor.height);
  msg.t_us = header.t_us;
  msg.newest_batch_seq = header.newest_batch_seq;
  msg.newest_batch_utime = header.newest_batch_utime;
}

// --- segment lists ---------------------------------------------------------------------------------

SegmentListPublisher::SegmentListPublisher(lcm::LCM& lcm, const LinesNodeOptions& options, std::int64_t epoch_us,
                                           LinesIngest& ingest, WholeLinePublisher* whole_lines)
    : lcm_(lcm),
      options_(options),
      epoch_us_(epoch_us),
      channel_(lines_channel(options.camera)),
      ingest_(ingest),
      whole_lines_(whole_lines) {}

void SegmentListPublisher::wait_for_round(const std::shared_ptr<RealtimeEngine>& engine,
                                          Clock::time_point until) const {
  engine->wait_for_round(published_engine_ == engine ? published_version_ : 0, until);
}

bool SegmentListPublisher::publish(bool heartbeat) {
  const auto engine = ingest_.engine();
  if (!engine) return false;  // nothing received yet
  const bool same_engine = engine == published_engine_;
  if (same_engine && !heartbeat && engine->lines_version() == published_version_)
    return false;  // no round since the last list
  const RealtimeEngine::LinesState state = engine->snapshot(lines_);
  published_engine_ = engine;
  published_version_ = state.version;
  fill_segment_list(lines_, msg_);
  const std::int64_t now = wall_clock_us();
  const LatencyTracker::Included included = ingest_.list_published(state.lattice_us, now);
  const ListHeader header{now, state.lattice_us, included.seq, included.utime, engine->geometry().sensor};
  fill_header(header, epoch_us_, options_.camera, seq_++, msg_);
  if (lcm_.publish(channel_, &msg_) == 0) published_.fetch_add(1, std::memory_order_relaxed);
  if (whole_lines_ != nullptr) hand_on(engine, header);
  return true;
}

void SegmentListPublisher::hand_on(const std::shared_ptr<RealtimeEngine>& engine, const ListHeader& header) {
  // Whole lines at most at their rate in wall time (up to a publish period early, so at equal
  // rates they go with every segment list) and in event time (up to a tracking period early): a
  // stream replayed slowly costs whole-line steps in proportion to its event time, as it does rounds.
  // While batches are being shed or thinned, at their lower rate: the service is past its means, and
  // the tracking rounds, whose lists the whole lines are built from, need the CPU first.
  const auto now = Clock::now();
  const std::uint64_t shed = ingest_.batches_over_budget();
  if (shed != shed_seen_) {
    if (shed_seen_ == 0 || now - last_shed_ >= kSheddingMemory) {
      spdlog::info("shedding: whole lines at most {} Hz until no batch has been shed or thinned for {} s",
                   options_.whole_lines_loaded_hz, std::chrono::duration<double>(kSheddingMemory).count());
    }
    shed_seen_ = shed;
    last_shed_ = now;
  }
  const bool shedding = shed_seen_ > 0 && now - last_shed_ < kSheddingMemory;
  const double whole_hz =
      shedding ? std::min(options_.whole_lines_hz, options_.whole_lines_loaded_hz) : options_.whole_lines_hz;
  const Timestamp event_period_us = static_cast<Timestamp>(1e6 / whole_hz) - engine->config().schedule.track_period_us;
  const Timestamp lattice_us = header.t_us;
  const bool due = now >= next_whole_list_ && (engine != whole_engine_handed_ || lattice_us < whole_time_handed_ ||
                                               lattice_us - whole_time_handed_ >= event_period_us);
  if (!due) return;
  next_whole_list_ = now + period_of(whole_hz) - period_of(options_.publish_hz);
  whole_engine_handed_ = engine;
  whole_time_handed_ = lattice_us;
  whole_lines_->hand_over(engine, lines_, header, shedding);
}

// --- the camera --------------------------------------------------------------------------------

CameraInfoPublisher::CameraInfoPublisher(lcm::LCM& lcm, const LinesNodeOptions& options, std::int64_t epoch_us)
    : lcm_(lcm), channel_(camera_info_channel(options.camera)) {
  msg_.epoch = epoch_us;
  msg_.source = options.camera;
}

bool CameraInfoPublisher::publish(const RealtimeEngine& engine) {
  const auto& table = engine.config().rectification;
  if (!table) return false;
  fill_camera_info(*table, msg_);
  msg_.utime = wall_clock_us();
  if (lcm_.publish(channel_, &msg_) == 0) ++published_;
  return true;
}

// --- whole lines -----------------------------------------------------------------------------------

WholeLinePublisher::WholeLinePublisher(lcm::LCM& lcm, const LinesNodeOptions& options, std::int64_t epoch_us,
                                       std::uint64_t first_id)
    : lcm_(lcm),
      options_(options),
      epoch_us_(epoch_us),
      channel_(whole_lines_channel(options.camera)),
      next_id_(first_id) {}

void WholeLinePublisher::hand_over(const std::shared_ptr<RealtimeEngine>& engine, std::span<const TrackedLine> lines,
                                   const ListHeader& header, bool shedding) {
  {
    std::lock_guard lock(mutex_);
    next_step_.engine = engine;
    next_step_.lines.assign(lines.begin(), lines.end());  // no allocation once as many lines were handed over
    next_step_.header = header;
    next_step_.shedding = shedding;
    waiting_ = true;
  }
  handed_.notify_one();
}

void WholeLinePublisher::loop(const std::atomic<bool>& stop) {
  name_this_thread("evldt-whole");
  run_this_thread_as_round();
  constexpr auto kLongestWait = std::chrono::milliseconds(100);  // the stop flag is checked this often
  while (!stop.load()) {
    {
      std::unique_lock lock(mutex_);
      if (!handed_.wait_for(lock, kLongestWait, [&] { return waiting_; })) continue;
      std::swap(step_, next_step_);  // the newest step; its buffers come back for the next
      waiting_ = false;
    }
    publish();
    published_.fetch_add(1, std::memory_order_relaxed);
    if (step_.shedding) while_shedding_.fetch_add(1, std::memory_order_relaxed);
  }
}

void WholeLinePublisher::publish() {
  const RealtimeEngine& engine = *step_.engine;
  // A new engine (camera restart, clock back) starts its whole lines afresh; ids go on, never repeated.
  if (step_.engine != staged_engine_ || (stage_ && step_.header.t_us < stage_->last_time())) {
    if (stage_) next_id_ += stage_->created();
    stage_.emplace(engine.config(), next_id_);
    staged_engine_ = step_.engine;
    const LatticeParams& lattice = engine.config().lattice;
    view_.emplace(lattice.sensor, lattice.block_size, lattice.alpha);
  }
  engine.copy_lattice(*view_);  // the events gaps are checked against
  fill_segment_list(stage_->step(step_.header.t_us, step_.lines, &*view_), msg_);
  fill_header(step_.header, epoch_us_, options_.camera, seq_++, msg_);  // that of the segment list the step was made of
  lcm_.publish(channel_, &msg_);
}

}  // namespace evldt
