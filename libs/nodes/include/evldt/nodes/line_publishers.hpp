#pragma once
// evldt-lines' two publishers. The segment-list publisher sends the engine's lines on
// LINES_<CAMERA> whenever a round changed them (at most at --publish-hz, at least once a second),
// and hands some of those lists to the whole-line publisher, which on a thread of its own (a
// whole-line step takes 3-4 ms at 1280x720 live, a segment list a fraction of one) joins them into
// whole lines and sends them on WHOLE_LINES_<CAMERA>, so that no segment list waits for one.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evldt/camera_info_t.hpp"
#include "evldt/nodes/lines_ingest.hpp"
#include "evldt/nodes/lines_options.hpp"
#include "evldt/pipeline/realtime_engine.hpp"
#include "evldt/pipeline/whole_line_stage.hpp"
#include "evldt/segment_list_t.hpp"

namespace evldt {

/// What a list says besides its lines: the same for a segment list and the whole lines made of it.
struct ListHeader {
  std::int64_t utime = 0;  ///< the segment list's publish time
  Timestamp t_us = 0;
  std::int64_t newest_batch_seq = -1, newest_batch_utime = 0;
  SensorSize sensor;
};

class WholeLinePublisher {
 public:
  /// Whole-line ids start at first_id and go on across engines, never repeated.
  WholeLinePublisher(lcm::LCM& lcm, const LinesNodeOptions& options, std::int64_t epoch_us, std::uint64_t first_id);

  /// Hands over the lines of the segment list just sent, replacing a step not begun yet.
  void hand_over(const std::shared_ptr<RealtimeEngine>& engine, std::span<const TrackedLine> lines,
                 const ListHeader& header, bool shedding);
  /// The whole-line thread: publishes each step handed over until `stop` (checked every 100 ms).
  void loop(const std::atomic<bool>& stop);

  [[nodiscard]] std::uint64_t published() const { return published_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t published_while_shedding() const {
    return while_shedding_.load(std::memory_order_relaxed);
  }

 private:
  struct Step {
    std::shared_ptr<RealtimeEngine> engine;
    std::vector<TrackedLine> lines;  ///< of a segment list, whose header the whole lines repeat
    ListHeader header;
    bool shedding = false;  ///< handed over at the lower rate
  };
  void publish();

  lcm::LCM& lcm_;
  const LinesNodeOptions& options_;
  std::int64_t epoch_us_;
  std::string channel_;

  std::condition_variable handed_;
  std::mutex mutex_;  // guards the two members below
  Step next_step_;
  bool waiting_ = false;
  std::atomic<std::uint64_t> published_{0}, while_shedding_{0};

  // Whole-line thread only.
  Step step_;
  std::optional<WholeLineStage> stage_;  ///< for the engine below (held, so a new one is told apart)
  std::shared_ptr<const RealtimeEngine> staged_engine_;
  std::optional<ScarfLattice> view_;  ///< the staged engine's lattice as of the last step
  std::uint64_t next_id_;
  segment_list_t msg_;
  std::int64_t seq_ = 0;
};

class SegmentListPublisher {
 public:
  /// `whole_lines`: where lists go on to be joined (nullptr: no whole lines).
  SegmentListPublisher(lcm::LCM& lcm, const LinesNodeOptions& options, std::int64_t epoch_us, LinesIngest& ingest,
                       WholeLinePublisher* whole_lines);

  /// Publishes the lines if a round changed them since the last list, or if `heartbeat` is set;
  /// true if it sent a list. Hands the list on to the whole lines when their rate allows.
  bool publish(bool heartbeat);
  /// Waits until `engine` has run a round the last list does not hold, or `until`.
  void wait_for_round(const std::shared_ptr<RealtimeEngine>& engine, std::chrono::steady_clock::time_point until) const;

  [[nodiscard]] std::size_t live_lines() const { return lines_.size(); }
  [[nodiscard]] std::uint64_t published() const { return published_.load(std::memory_order_relaxed); }

 private:
  /// Whether this list also goes to the whole lines, and at which rate (the lower while shedding).
  void hand_on(const std::shared_ptr<RealtimeEngine>& engine, const ListHeader& header);

  lcm::LCM& lcm_;
  const LinesNodeOptions& options_;
  std::int64_t epoch_us_;
  std::string channel_;
  LinesIngest& ingest_;
  WholeLinePublisher* whole_lines_;

  std::vector<TrackedLine> lines_;
  segment_list_t msg_;
  std::int64_t seq_ = 0;
  std::uint64_t published_version_ = 0;  ///< the engine's lines version in the last list
  std::shared_ptr<const RealtimeEngine> published_engine_;
  std::atomic<std::uint64_t> published_{0};
  std::chrono::steady_clock::time_point next_whole_list_{};
  std::shared_ptr<const RealtimeEngine> whole_engine_handed_;  ///< of the last whole-line step handed over
  Timestamp whole_time_handed_ = 0;                            ///< its lattice time
  std::uint64_t shed_seen_ = 0;                                ///< batches shed when the publisher last looked
  std::chrono::steady_clock::time_point last_shed_{};          ///< when it last saw that number grow
};

/// The calibrated camera the lines are given in, on CAMERA_INFO_<CAMERA> (camera_info_t), for an
/// engine that has a calibration.
class CameraInfoPublisher {
 public:
  CameraInfoPublisher(lcm::LCM& lcm, const LinesNodeOptions& options, std::int64_t epoch_us);
  /// Publishes the camera of `engine`'s calibration; false (nothing sent) without one.
  bool publish(const RealtimeEngine& engine);
  [[nodiscard]] std::uint64_t published() const { return published_; }

 private:
  lcm::LCM& lcm_;
  std::string channel_;
  camera_info_t msg_{};
  std::uint64_t published_ = 0;
};

/// The list header's fields of a segment_list_t.
void fill_header(const ListHeader& header, std::int64_t epoch_us, const std::string& camera, std::int64_t seq,
                 segment_list_t& msg);

/// A rate's period on the steady clock.
std::chrono::steady_clock::duration period_of(double hz);

}  // namespace evldt
