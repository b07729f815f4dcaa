#pragma once
// The pipeline's last stage: each output step's block segments joined into whole lines. The one
// place a whole-line tracker is made from a pipeline's configuration, for the deterministic
// pipeline (evldt-offline, evldt-eval, evldt-bench, Python) and the live service alike.

#include <cstdint>
#include <span>
#include <vector>

#include "evldt/lines/whole_lines.hpp"
#include "evldt/pipeline/pipeline_config.hpp"

namespace evldt {

class WholeLineStage {
 public:
  /// Ids start at first_id (the live service folds its start time in, as for segment ids).
  explicit WholeLineStage(const PipelineConfig& config, std::uint64_t first_id = 1);

  /// One output step: the segments tracked at time t on `lattice` (nullptr: on geometry alone; see
  /// WholeLineTracker::update). Returns the whole lines published at this step.
  std::span<const TrackedLine> step(Timestamp t, std::span<const TrackedLine> segments, const ScarfLattice* lattice);

  /// The whole lines of the last step as rows of the segment format: score = the number of block
  /// segments joined, status good, admin block -1.
  [[nodiscard]] std::span<const TrackedLine> lines() const { return lines_; }
  /// Time of the last step (0 before the first).
  [[nodiscard]] Timestamp last_time() const { return tracker_.last_time(); }
  /// Distinct ids published so far.
  [[nodiscard]] std::uint64_t created() const { return tracker_.created(); }

 private:
  WholeLineTracker tracker_;
  std::vector<TrackedLine> lines_;
};

}  // namespace evldt
