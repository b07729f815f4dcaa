#pragma once
// Line detection (DESIGN 3): per free block, a robust line fit clipped to the block, kept when its
// fitting score clears the threshold. A block whose entries have not changed since it last failed
// is skipped: the fit and the score depend on nothing else, so it would fail again.

#include <cstdint>
#include <vector>

#include "evldt/lines/fitting_score.hpp"
#include "evldt/lines/line_map.hpp"
#include "evldt/lines/params.hpp"

namespace evldt {

class LineDetector {
 public:
  LineDetector(const LatticeGeometry& geometry, const ScoreParams& params);

  /// One detection round over every block; returns the number of lines created.
  int detect(const ScarfLattice& lattice, LineMap& lines, Timestamp now);

 private:
  LatticeGeometry geometry_;
  ScoreParams params_;
  FittingScorer scorer_;
  PointSet points_;  // scratch: the active entries of the current block
  std::uint64_t versions_of_ = 0;               // the lattice whose block versions failed_at_ holds
  std::vector<std::uint64_t> failed_at_;        // per block: its version at its last failed attempt
};

}  // namespace evldt
