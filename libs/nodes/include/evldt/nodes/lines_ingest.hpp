#pragma once
// evldt-lines' ingest: the event batches LCM hands over are queued at once (its handler only copies
// them), then received on the storing thread (decoded, checked, held to the latency budget: thinned
// or shed) and stored in the real-time engine, which the ingest makes at the first batch (or at
// start for a configured sensor) and anew when the camera restarts or its clock goes back.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>

#include "evldt/nodes/lines_options.hpp"
#include "evldt/pipeline/realtime_engine.hpp"
#include "evldt/transport/payload_queue.hpp"

namespace evldt {

class LinesIngest {
 public:
  /// The lines of the first engine are numbered from first_line_id; those of a restarted one go on.
  LinesIngest(const LinesNodeOptions& options, std::uint64_t first_line_id);
  ~LinesIngest();
  LinesIngest(const LinesIngest&) = delete;
  LinesIngest& operator=(const LinesIngest&) = delete;

  /// LCM's handler: queues a batch's payload, received at `received_utime` (wall clock), waiting while
  /// the queue is full (until `stop`).
  void queue(std::span<const std::uint8_t> payload, std::int64_t received_utime, const std::atomic<bool>& stop);
  /// The storing thread: stores the queued batches until `stop` is set (checked every 100 ms).
  void store_loop(const std::atomic<bool>& stop);
  /// Stops the engine's rounds (idempotent).
  void stop_engine();

  /// The current engine; nullptr before the first batch.
  [[nodiscard]] std::shared_ptr<RealtimeEngine> engine() const;
  /// Waits until an engine has started or `until`.
  void wait_for_engine(std::chrono::steady_clock::time_point until);
  /// Batches shed or thinned over the latency budget so far.
  [[nodiscard]] std::uint64_t batches_over_budget() const;
  /// A segment list of the lattice at `lattice_us` went out at `now_us`: the newest batch it includes.
  LatencyTracker::Included list_published(Timestamp lattice_us, std::int64_t now_us);
  /// The latency of the lists since the last call.
  LatencySummary take_latency_summary();
  /// The receiver's, the engines' and the latency figures of `totals`.
  void add_to(LinesNodeTotals& totals) const;

 private:
  /// Decodes one queued batch and stores it, thinned or shed if it queued longer than the budget.
  void store(const PayloadQueue::Queued& payload);
  void start_engine();
  /// A started engine for `sensor` whose lines are numbered from `first_line_id`.
  [[nodiscard]] std::shared_ptr<RealtimeEngine> make_engine(SensorSize sensor, std::uint64_t first_line_id) const;

  const LinesNodeOptions& options_;
  PayloadQueue queue_;

  // Storing thread only.
  EventBatchReceiver receiver_;
  LatencyBudget budget_;
  EventBatch batch_;
  std::shared_ptr<RealtimeEngine>
      prebuilt_;                     ///< built and started at start for a configured sensor, for the first batch
  std::uint64_t sizes_refused_ = 0;  ///< batches of a sensor size the configuration refused

  mutable std::mutex mutex_;  // guards the members below (the storing thread alone writes them)
  std::uint64_t next_line_id_;
  std::shared_ptr<RealtimeEngine> engine_;
  std::condition_variable engine_started_;
  ReceiverCounts receiver_counts_;
  LatencyTracker latency_;
  std::uint64_t engine_restarts_ = 0;
  EngineCounters retired_;  ///< summed over the engines of earlier camera epochs
};

}  // namespace evldt
