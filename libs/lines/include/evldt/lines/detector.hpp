#pragma once
// Line detection (docs/design.md, section 4): per free block, a robust line fit clipped to the block, kept when its
// fitting score clears the threshold. A block whose entries have not changed since it last failed
// is skipped: the fit and the score depend on nothing else, so it would fail again. Nor is it
// fitted again before it gained ScoreParams::retry_share of N new active entries: a few new events
// leave it nearly the same test, and every retry is one more chance for stale or noise events to
// clear f_th by luck (docs/accuracy.md, recall per true edge).

#include <cstdint>
#include <vector>

#include "evldt/lines/bend_test.hpp"
#include "evldt/lines/fitting_score.hpp"
#include "evldt/lines/line_map.hpp"
#include "evldt/lines/params.hpp"
#include "evldt/lines/round_workers.hpp"

namespace evldt {

class LineDetector {
 public:
  /// With workers, a round's block rows are shared out among its workers (no two touch one block);
  /// the lines are then created in block order, so the output is the same for any count. The workers
  /// must outlive the detector.
  LineDetector(const LatticeGeometry& geometry, const ScoreParams& params, RoundWorkers* workers = nullptr);

  /// One detection round over every block; returns the number of lines created. Without
  /// `test_bends` a block's line that clears the score is kept without the bend test (the live
  /// engine while it sheds: the test reads the blocks beyond both ends of every new line).
  int detect(const ScarfLattice& lattice, LineMap& lines, Timestamp now, bool test_bends = true);

  /// A lattice of fewer blocks is detected on the calling thread: waking the workers would cost more.
  static constexpr int kMinBlocksToSplit = 1024;

 private:
  /// One worker's scratch.
  struct Worker {
    FittingScorer scorer;
    BendTest bend;
    PointSet points;  // the active entries of the current block
  };
  /// A block's new line of this round, until it is added.
  struct Found {
    bool present = false;
    float score = 0;
    Segment segment;
  };
  void detect_row(const ScarfLattice& lattice, LineMap& lines, int row, Worker& worker, bool test_bends);

  LatticeGeometry geometry_;
  ScoreParams params_;
  RoundWorkers* round_workers_;
  std::vector<Worker> workers_;
  std::uint64_t versions_of_ = 0;               // the lattice whose block versions failed_at_ holds
  std::vector<std::uint64_t> failed_at_;        // per block: its version at its last failed attempt
  std::vector<std::uint16_t> failed_arrivals_;  // per block: its ScarfLattice::active_arrivals at that attempt
  std::uint16_t retry_after_;                   // new active entries before a failed block is fitted again
  std::vector<Found> found_;                    // per block
};

}  // namespace evldt
