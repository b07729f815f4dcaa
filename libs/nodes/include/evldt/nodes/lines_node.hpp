#pragma once
// The evldt-lines service without its command line: subscribes to one camera's event batches,
// queues each as it arrives (LCM's handler only copies it), stores them in the real-time engine on
// a thread of their own (which never waits for a detection or tracking pass), sheds the batches
// that come later than its latency budget, and publishes the
// live segments whenever a round changed them (at most at a set rate, at least once a second) and
// its statistics once a second.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>
#include <sys/types.h>

#include "evldt/lines/realtime_engine.hpp"
#include "evldt/lines/whole_line_stage.hpp"
#include "evldt/transport/event_batch_receiver.hpp"
#include "evldt/transport/latency_tracker.hpp"
#include "evldt/transport/payload_queue.hpp"

namespace evldt {

/// The default latency budget: well above the queueing of a service that keeps up (a few ms), well
/// below answers too old to steer by (docs/realtime.md).
inline constexpr double kDefaultMaxLatencyMs = 20;

struct LinesNodeOptions {
  std::string camera = "cam0";
  std::optional<SensorSize> sensor;  ///< unset: adopt the first valid batch's (set: the engine is built at start)
  std::function<PipelineConfig(SensorSize)> configure = default_config_for;
  Timestamp time_slack_us = 1000;
  double publish_hz = 100;  ///< at most this many segment lists a second: one after each round, when rounds are faster
  /// Batches that queued longer than this before they could be stored are thinned, past twice it
  /// shed whole (LatencyBudget; 0: never).
  double max_latency_ms = kDefaultMaxLatencyMs;
  OverloadPolicy overload = OverloadPolicy::Thin;
  double stats_hz = 1;
  double log_period_s = 10;  ///< a status line in the log this often (0: never)
  bool whole_lines = true;   ///< also publish whole lines on WHOLE_LINES_<CAMERA>
  /// Whole-line lists per second at most: with a segment list, once 1 / whole_lines_hz has passed since
  /// the last (a whole-line step costs 1.8 ms at HD; lines change little in 1 ms).
  double whole_lines_hz = 100;
  /// While the service sheds (a batch shed within the last second), whole lines go out at most this
  /// often: at HD they took a quarter of a core at 100 Hz, which the tracking rounds need more.
  double whole_lines_loaded_hz = 10;
};

/// Totals since start (what the stats message and the exit summary report).
struct LinesNodeTotals {
  ReceiverCounts receiver;           ///< batches received, lost, invalid and shed
  std::uint64_t events_received = 0;  ///< valid events handed to the engine
  FilterCounts filtered;              ///< what the noise filters dropped of them
  std::uint64_t events_stored = 0;
  std::uint64_t detect_rounds = 0;
  std::uint64_t detect_rounds_without_bend_test = 0;  ///< run while shedding
  std::uint64_t track_rounds = 0;
  std::uint64_t lines_created = 0;
  std::uint64_t lists_published = 0;
  std::uint64_t whole_lists_published = 0;
  std::uint64_t whole_lists_while_shedding = 0;  ///< of them, published at whole_lines_loaded_hz
  std::uint64_t engine_restarts = 0;  ///< the camera restarted (new epoch): the lattice began afresh
  LatencySummary latency;             ///< batch publish -> first list including it, since the last camera (re)start
  LatencySummary settled_latency;     ///< the same, of the batches published 1 s or more after the first (LatencyTracker)

  /// The exit summary, with the options it was run with.
  void print(std::FILE* out, const LinesNodeOptions& options) const;
};

class LinesNode {
 public:
  /// Subscribes at once. `epoch_us` (the process start) is sent in every message and is the first
  /// line id, so a restarted process never repeats an id.
  LinesNode(lcm::LCM& lcm, LinesNodeOptions options, std::int64_t epoch_us);
  ~LinesNode();
  LinesNode(const LinesNode&) = delete;
  LinesNode& operator=(const LinesNode&) = delete;

  /// Receives, stores and publishes until `stop` is set (checked every 100 ms), then stops the engine.
  void run(const std::atomic<bool>& stop);
  [[nodiscard]] LinesNodeTotals totals() const;

 private:
  /// Makes real-time the threads started since `threads_before` was taken (LCM's socket reader).
  static void make_socket_readers_realtime(const std::vector<pid_t>& threads_before);
  void on_events(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void store_loop(const std::atomic<bool>& stop);
  /// Decodes one queued batch and stores it, or sheds it if it queued longer than the budget.
  void store(std::span<const std::uint8_t> payload);
  void start_engine();
  /// A started engine for `sensor` whose lines are numbered from `first_line_id`.
  [[nodiscard]] std::shared_ptr<RealtimeEngine> make_engine(SensorSize sensor, std::uint64_t first_line_id) const;
  void publish_loop(const std::atomic<bool>& stop);
  /// Publishes the lines if a round changed them since the last list, or if `heartbeat` is set;
  /// true if it sent a list.
  bool publish_segments(bool heartbeat);
  /// What a list says besides its lines: the same for a segment list and the whole lines made of it.
  struct ListHeader {
    std::int64_t utime = 0;  ///< the segment list's publish time
    Timestamp t_us = 0;
    std::int64_t newest_batch_seq = -1, newest_batch_utime = 0;
    SensorSize sensor;
  };
  void fill_header(const ListHeader& header, std::int64_t seq, segment_list_t& msg) const;
  /// Hands the lines of the list just sent to the whole-line thread, replacing a step it has not begun.
  void hand_over_whole_step(const std::shared_ptr<RealtimeEngine>& engine, const ListHeader& header, bool shedding);
  void whole_line_loop(const std::atomic<bool>& stop);
  void publish_whole_lines();
  void publish_stats(double period_s);
  [[nodiscard]] std::shared_ptr<RealtimeEngine> engine() const;

  lcm::LCM& lcm_;
  LinesNodeOptions options_;
  std::int64_t epoch_us_;
  std::string lines_channel_;
  std::string whole_lines_channel_;
  lcm::Subscription* subscription_ = nullptr;

  // The thread that handles LCM queues batches here; the store thread takes them.
  PayloadQueue queue_;
  const std::atomic<bool>* stop_ = nullptr;  ///< run()'s, which the handler waits on when the queue is full

  // Store thread only.
  EventBatchReceiver receiver_;
  LatencyBudget budget_;
  EventBatch batch_;
  std::shared_ptr<RealtimeEngine> prebuilt_;  ///< built and started at start for a configured sensor, for the first batch

  mutable std::mutex mutex_;  // guards the members below (the store thread alone writes them)
  std::uint64_t next_line_id_;
  std::shared_ptr<RealtimeEngine> engine_;
  std::condition_variable engine_started_;  ///< wakes the publisher, which waits for the first engine
  ReceiverCounts receiver_counts_;
  LatencyTracker latency_;
  std::uint64_t engine_restarts_ = 0;
  EngineCounters retired_;  ///< summed over the engines of earlier camera epochs

  // Publish thread only.
  std::vector<TrackedLine> lines_;
  segment_list_t list_msg_;
  std::int64_t list_seq_ = 0;
  std::uint64_t published_version_ = 0;  ///< the engine's lines version in the last list
  std::shared_ptr<const RealtimeEngine> published_engine_;
  std::atomic<std::uint64_t> lists_published_{0};
  std::chrono::steady_clock::time_point next_whole_list_{};
  std::shared_ptr<const RealtimeEngine> whole_engine_handed_;  ///< of the last whole-line step handed over
  Timestamp whole_time_handed_ = 0;                            ///< its lattice time
  std::uint64_t shed_seen_ = 0;                          ///< batches shed when the publisher last looked
  std::chrono::steady_clock::time_point last_shed_{};    ///< when it last saw that number grow
  LinesNodeTotals last_stats_;
  LatencySummary last_latency_;  ///< of the last statistics message, for the log line

  // A whole-line step runs on a thread of its own (3-4 ms at 1280x720 live, against a segment
  // list's fraction of a millisecond), so that no segment list waits for one.
  struct WholeLineStep {
    std::shared_ptr<RealtimeEngine> engine;
    std::vector<TrackedLine> lines;  ///< of a segment list, whose header the whole lines repeat
    ListHeader header;
    bool shedding = false;  ///< handed over at the lower rate
  };
  std::condition_variable whole_step_handed_;
  std::mutex whole_mutex_;  // guards the two members below
  WholeLineStep next_whole_step_;
  bool whole_step_waiting_ = false;
  std::atomic<std::uint64_t> whole_lists_published_{0}, whole_lists_while_shedding_{0};

  // Whole-line thread only.
  WholeLineStep whole_step_;
  std::optional<WholeLineStage> joiner_;  ///< for the engine below (held, so a new one is told apart)
  std::shared_ptr<const RealtimeEngine> joined_engine_;
  std::optional<ScarfLattice> whole_view_;  ///< the joined engine's lattice as of the last whole-line step
  std::uint64_t next_whole_id_;
  segment_list_t whole_msg_;
  std::int64_t whole_seq_ = 0;
};

}  // namespace evldt
