#pragma once
// The real-time engine (docs/design.md, section 7): the caller's thread filters and stores events as they arrive
// while detection and tracking loop on their own threads, each starting a round once a period of
// event time has been stored since its last (or, when the input pauses, on whatever is new). So
// the rounds follow the events: a stream replayed at a tenth of real time costs a tenth of the
// rounds; while the caller sheds batches it cannot store in time, the rounds run
// ScheduleParams::shedding_period_factor periods apart, leaving the CPU to storage, and detection
// keeps new lines without the bend test (bend_test.hpp); the same while it thins batches. Each loop works
// on its own copy of the lattice, brought up to date before each round (by the storing thread when
// the loop asks while a batch is being stored), so storage never waits for a pass, nor for a copy
// by a preempted thread of lower priority, and a round always starts from the newest state: rounds
// never queue. The loops run at the process's priority (evldt-lines raises
// storage's above it). The line state is shared by the two loops under a second lock.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "evldt/lines/detector.hpp"
#include "evldt/lines/tracker.hpp"
#include "evldt/pipeline/event_intake.hpp"
#include "evldt/pipeline/pipeline_config.hpp"
#include "evldt/pipeline/worker_pool.hpp"

namespace evldt {

struct EngineCounters {
  FilterCounts filtered;              ///< what the noise filters let through and dropped
  std::uint64_t events_received = 0;  ///< handed to process()
  std::uint64_t events = 0;           ///< stored
  std::uint64_t off_rectified = 0;    ///< with a calibration: left out, their pixel feeds no rectified pixel
  std::uint64_t detect_rounds = 0;
  std::uint64_t detect_rounds_without_bend_test = 0;  ///< those run while shedding
  std::uint64_t track_rounds = 0;
  std::uint64_t lines_created = 0;
  Timestamp latest_event_us = 0;
  Timestamp detected_us = 0;  ///< event time of the lattice the last detection round ran on
  Timestamp tracked_us = 0;   ///< event time of the lattice the last tracking round ran on
};

class RealtimeEngine {
 public:
  explicit RealtimeEngine(const PipelineConfig& config);
  ~RealtimeEngine();
  RealtimeEngine(const RealtimeEngine&) = delete;
  RealtimeEngine& operator=(const RealtimeEngine&) = delete;

  void start();
  void stop();  ///< joins the loops; idempotent

  /// Filters and stores on-sensor, time-ordered events (from one producer thread), each `copies`
  /// times (a thinned batch: stored_copies()).
  void process(const EventBatch& input, int copies = 1);
  /// How many times each event of a batch thinned to every stride-th is stored: stride / 2, at least
  /// once. A block's ring then fills at half the pace of the whole stream at any stride, so it never
  /// reaches back more than twice the time it would unthinned. Kept once, every 4th event made the
  /// rings reach back four times as far, past edges that had moved on; stored 4 times, the rings
  /// held a quarter of the distinct events, too few on sparse and noisy scenes. Chosen on the model
  /// of `evldt-eval --thin` over five scenes (docs/realtime.md): every 2nd event once and every 4th
  /// twice gave the best mean F@1%.
  static int stored_copies(int stride) { return stride / 2 > 1 ? stride / 2 : 1; }
  /// Events up to `until_us` were shed unstored (over the latency budget): event time still moves on.
  void shed(Timestamp until_us);
  /// The service is past its means at event time `at_us` (it stored a batch thinned, or shed one):
  /// the rounds run further apart for a while (ScheduleParams::shedding_period_factor).
  void note_overload(Timestamp at_us);

  struct LinesState {
    Timestamp lattice_us = 0;   ///< event time of the lattice state the lines were last tracked or detected on
    std::uint64_t version = 0;  ///< rounds finished so far: equal values, equal lines
  };
  /// Copies the live lines into `out` (reusing its capacity).
  LinesState snapshot(std::vector<TrackedLine>& out) const;
  /// The version snapshot() would return now, without copying (a publisher skips an unchanged state).
  [[nodiscard]] std::uint64_t lines_version() const { return lines_version_.load(std::memory_order_acquire); }
  /// Waits, without using the CPU, until a round has finished past `version`, or until `deadline`.
  void wait_for_round(std::uint64_t version, std::chrono::steady_clock::time_point deadline) const;
  [[nodiscard]] EngineCounters counters() const;
  /// The pixels the hot-pixel filter masks now (y * width + x).
  [[nodiscard]] std::vector<std::uint32_t> masked_pixels() const;
  [[nodiscard]] const LatticeGeometry& geometry() const { return lattice_.geometry(); }
  /// Brings `view`, a lattice of this engine's geometry, up to the stored one (copying only the
  /// blocks changed since its last copy): the events a publisher's whole lines check gaps against.
  void copy_lattice(ScarfLattice& view) const;
  [[nodiscard]] const PipelineConfig& config() const { return config_; }
  /// Folds a per-start epoch into line ids so a restarted process never repeats one.
  void set_first_line_id(std::uint64_t first);

 private:
  /// A round loop's view of the lattice and its hand-over; guarded by lattice_mutex_ except the
  /// view itself while the loop runs a round on it.
  struct LoopState {
    ScarfLattice view;
    // Event time at which the loop, while it waits, wants to be woken: storage wakes the loops only
    // when a round may be due, not at every batch.
    Timestamp wake_at_us = 0;
    bool view_wanted = false;  // the loop waits for storage to copy the lattice into its view
    bool view_ready = false;   // storage did: the view holds the lattice as of view_seen / view_us
    std::uint64_t view_seen = 0;
    Timestamp view_us = 0;
    std::atomic<Timestamp> last_round_us{0};  // event time of the view the last round ran on
  };

  void note_input(const EventBatch& input);  // under lattice_mutex_
  /// Copies the lattice into the view of each loop that wants one; whether any did. Under lattice_mutex_.
  bool hand_over_views();
  void take_view(LoopState& loop);  // under lattice_mutex_
  template <typename Round>
  void loop(const char* thread_name, LoopState& state, std::atomic<std::uint64_t>& rounds, Timestamp period_us,
            Round round);

  PipelineConfig config_;
  mutable std::mutex intake_mutex_;  // the producer filters under it; counters() reads under it
  EventIntake intake_;               // guarded by intake_mutex_
  ScarfLattice lattice_;             // guarded by lattice_mutex_
  mutable std::mutex lattice_mutex_;
  std::condition_variable lattice_changed_;
  std::uint64_t events_stored_ = 0;    // guarded by lattice_mutex_
  std::uint64_t events_received_ = 0;  // stored or filtered; guarded by lattice_mutex_
  Timestamp latest_event_us_ = 0;      // guarded by lattice_mutex_
  static constexpr Timestamp kNeverShed = std::numeric_limits<Timestamp>::min();
  // Rounds stay further apart until this much event time has passed without a batch shed.
  static constexpr Timestamp kSheddingMemoryUs = 1'000'000;
  Timestamp last_overload_us_ = kNeverShed;  // event time of the last batch shed or thinned; guarded by lattice_mutex_
  bool stopping_ = false;                    // guarded by lattice_mutex_
  std::atomic<bool> storing_{false};         // process() is running: a loop lets it copy the views
  LoopState detect_, track_;

  mutable std::mutex lines_mutex_;
  LineMap lines_;                                // guarded by lines_mutex_
  WorkerPool pool_;                              // config.threads: the loops take turns with it
  LineDetector detector_;                        // used only under lines_mutex_
  LineTracker tracker_;                          // used only under lines_mutex_
  Timestamp lines_time_us_ = 0;                  // guarded by lines_mutex_
  std::atomic<std::uint64_t> lines_version_{0};  // written under lines_mutex_
  mutable std::condition_variable round_done_;   // with lines_mutex_

  std::atomic<std::uint64_t> detect_rounds_{0}, track_rounds_{0}, detect_rounds_without_bend_test_{0};
  std::thread detect_thread_, track_thread_;
};

}  // namespace evldt
