#pragma once
// Line tracking (docs/design.md, section 5): every live line tries its current segment and four endpoint
// perturbations along the lattice lines its endpoints sit on, keeps the best-scoring one, and the
// manager then settles ownership and suppression.

#include <cstdint>
#include <vector>

#include "evldt/lines/fitting_score.hpp"
#include "evldt/lines/line_map.hpp"
#include "evldt/lines/params.hpp"
#include "evldt/lines/round_workers.hpp"

namespace evldt {

/// Appends to `cells` the lattice blocks the segment passes through, in order from q0 (exact grid
/// traversal; endpoints lying on a border count for the block on the segment's side).
void blocks_along(const Segment& segment, const LatticeGeometry& geometry, std::vector<int>& cells);

/// Where an endpoint may move: `base` is the endpoint snapped onto its lattice line, `step` the
/// perturbation vector along that line (dq along x on a horizontal border, along y on a vertical one;
/// within 1 px of a block corner, along the axis closest to the segment normal).
struct EndpointMotion {
  Point2 base;
  Point2 step;
};
EndpointMotion endpoint_motion(const Point2& endpoint, const Point2& segment_direction, const LatticeGeometry& geometry,
                               float perturbation_px);

/// Distance from a line centre to a neighbouring block below which that block is suppressed (docs/design.md, section
/// 5).
inline constexpr float kSuppressRatio = 0.4f;

class LineTracker {
 public:
  /// With workers, a round's lines are tracked by its workers; the output is the same for any count.
  /// The workers must outlive the tracker.
  LineTracker(const LatticeGeometry& geometry, const ScoreParams& score, const TrackParams& track,
              RoundWorkers* workers = nullptr);

  /// One tracking round over every line, followed by the manager. A line whose blocks have not
  /// changed since a pass that left it in place is not scored again: the pass would repeat itself.
  void track(const ScarfLattice& lattice, LineMap& lines, Timestamp now);
  /// Line passes that reused a settled line's score instead of scoring it again.
  [[nodiscard]] std::uint64_t settled_passes() const;

  /// A round with fewer lines runs on the calling thread: waking the workers would cost more.
  static constexpr std::size_t kMinLinesToSplit = 64;

 private:
  /// One worker's scratch.
  struct Worker {
    FittingScorer scorer;
    std::vector<int> cells;  // blocks under the current line
    PointSet points;         // the event set of the current line
    std::uint64_t settled_passes = 0;
  };
  /// Tracks one line; false when it must be released (reason set). settled_version: its
  /// LineMap::settled_version; settled_ok: versions of this lattice may be compared with it.
  bool track_line(const ScarfLattice& lattice, TrackedLine& line, std::uint64_t& settled_version, Point2& band_centre,
                  Timestamp now, bool settled_ok, Worker& worker, ReleaseReason& reason) const;
  /// Status after a pass that left line.score: good, or bad and released once out of patience.
  bool judge(TrackedLine& line, Timestamp now, ReleaseReason& reason) const;

  LatticeGeometry geometry_;
  ScoreParams score_params_;
  TrackParams params_;
  RoundWorkers* round_workers_;
  std::vector<Worker> workers_;
  /// Per line of the round: kKept, or the ReleaseReason it ends with. Lines are tracked first and
  /// released after, in the order one pass down the list would release them.
  std::vector<std::uint8_t> outcome_;
  std::uint64_t versions_of_ = 0;  // ScarfLattice::versions_of() at the last round
};

}  // namespace evldt
