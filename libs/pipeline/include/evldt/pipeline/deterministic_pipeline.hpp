#pragma once
// The deterministic pipeline (docs/design.md, section 7), its stages composed in this one place:
// the noise filters, with a calibration the move into the rectified image, storage of every event
// that passes them in the lattice, tracking every track_period_us and detection every
// detect_period_us of EVENT time, and at each output step, when asked for, the whole lines; so a
// run's output depends only on its input.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "evldt/lines/detector.hpp"
#include "evldt/lines/tracker.hpp"
#include "evldt/pipeline/event_intake.hpp"
#include "evldt/pipeline/pipeline_config.hpp"
#include "evldt/pipeline/whole_line_stage.hpp"
#include "evldt/pipeline/worker_pool.hpp"

namespace evldt {

struct PipelineCounters {
  std::uint64_t events = 0;
  std::uint64_t track_rounds = 0;
  std::uint64_t detect_rounds = 0;
  std::uint64_t skipped_rounds = 0;  ///< rounds not run across long gaps in event time
  std::uint64_t clock_restarts = 0;  ///< schedules begun again because event time went back
  std::uint64_t off_rectified = 0;   ///< with a calibration: events whose pixel feeds no rectified pixel
};

/// A batch starting this far before the next due round means the clock went back (an EventValidator
/// only lets that through when it follows a clock reset): the round schedule begins again there.
inline constexpr Timestamp kClockStepBackUs = 1'000'000;

/// The state after every round due at an output step's time.
struct OutputStep {
  Timestamp t;
  const LineMap& segments;
  std::span<const TrackedLine> whole_lines;  ///< empty unless whole lines were asked for
  const ScarfLattice& lattice;
};

class DeterministicPipeline {
 public:
  using StepCallback = std::function<void(const OutputStep& step)>;

  explicit DeterministicPipeline(const PipelineConfig& config, bool keep_surface = false);

  /// Adds an output step at every multiple of period_us of event time after the first event (0
  /// disables it): the steps fall on the same clock grid as ground truth sampled every period_us.
  /// With whole_lines, each step also joins its segments into whole lines (WholeLineStage).
  void set_output(Timestamp period_us, StepCallback on_step, bool whole_lines = false);

  /// Feeds on-sensor events in time order (an EventValidator upstream guarantees both) through the
  /// filters into storage. A round due at time T sees exactly the stored events with t < T. After a
  /// clock reset upstream, the schedule begins again at the first batch more than kClockStepBackUs
  /// behind it. `copies`: each event is stored that many times (a thinned batch, as
  /// RealtimeEngine::stored_copies says).
  void process(const EventBatch& batch, int copies = 1);
  /// process() in two stages, the first of which may run on another thread, a few batches ahead:
  /// filter() runs the noise filters alone (the only state it touches), process_filtered() stores
  /// what passed and runs the rounds, with `batch` as given to filter() (its times move the schedule
  /// on). Called in the same order, they give process()'s output.
  void filter(const EventBatch& batch, EventBatch& filtered);
  void process_filtered(const EventBatch& batch, const EventBatch& filtered, int copies = 1);

  [[nodiscard]] const LineMap& lines() const { return lines_; }
  [[nodiscard]] LineMap& lines() { return lines_; }
  [[nodiscard]] const ScarfLattice& lattice() const { return lattice_; }
  [[nodiscard]] const PipelineCounters& counters() const { return counters_; }
  [[nodiscard]] FilterCounts filter_counts() const { return intake_.filter_counts(); }
  [[nodiscard]] const FilterChain& filters() const { return intake_.filters(); }
  [[nodiscard]] const PipelineConfig& config() const { return config_; }
  /// The whole-line stage, when set_output asked for whole lines.
  [[nodiscard]] const WholeLineStage* whole_lines() const { return whole_lines_ ? &*whole_lines_ : nullptr; }

 private:
  void start_or_restart(const EventBatch& batch);  // at a batch's first event
  void store(const EventBatch& batch, int copies);
  void finish_batch(const EventBatch& batch);  // the rounds due by its last event
  void start(Timestamp t0);
  void run_rounds_until(Timestamp t);  // every round due at a time <= t
  void skip_gap(Timestamp resume_from);
  void update_next_due();

  PipelineConfig config_;
  EventIntake intake_;
  ScarfLattice lattice_;
  LineMap lines_;
  WorkerPool pool_;  // config.threads; shared by the detector and the tracker
  LineDetector detector_;
  LineTracker tracker_;
  PipelineCounters counters_;
  std::optional<WholeLineStage> whole_lines_;
  StepCallback on_step_;
  Timestamp output_period_ = 0;
  bool started_ = false;
  Timestamp next_track_ = 0, next_detect_ = 0, next_output_ = 0;
  Timestamp next_due_ = 0;  ///< min of the three: the only comparison made per event
};

}  // namespace evldt
