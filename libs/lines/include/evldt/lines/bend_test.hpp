#pragma once
// Whether a block's line is a piece of a curve (issue 27, curves): the events beyond its ends.
//
// A block holds too short a stretch of an edge to tell an arc from a line: a circle of radius 5 b
// is 0.03 b off the chord across one block, well inside the inlier band, so arcs are detected and
// tracked as lines. Beyond the block the arc bends away: over a span of 3 b it is 0.2 b off. The test
// fits v = a + t u + c u^2 (u along the segment, v across) robustly to the lattice events of a band
// around the segment extended by b at each end, and calls the segment bent when
//   - the edge does not run on straight beyond either end (parallel edges and a corner's other edge
//     may lie in the band too: an edge that continues on the segment's line is no arc),
//   - the curve's middle is far enough off the chord (c) and it does not rise at one end alone (t:
//     the column of a corner's other edge),
//   - events follow the curve beyond both ends.

#include <Eigen/Core>
#include <vector>

#include "evldt/lines/geometry.hpp"
#include "evldt/lines/params.hpp"
#include "evldt/lines/point_set.hpp"
#include "evldt/scarf/scarf_lattice.hpp"

namespace evldt {

class BendTest {
 public:
  /// max_bend_ratio: ScoreParams::max_bend_ratio (0: never bent).
  BendTest(const LatticeGeometry& geometry, float max_bend_ratio);

  /// True when `segment` is a stretch of an edge that bends away to one side beyond both of its ends.
  bool bent(const ScarfLattice& lattice, const Segment& segment);

 private:
  bool runs_on_straight(float length);
  bool followed_beyond_both_ends(const Eigen::Vector3d& curve, float length, float half_span);

  LatticeGeometry geometry_;
  float min_bend_px_;
  std::vector<int> cells_;  // scratch: the blocks along the extended segment
  PointSet points_;         // scratch: their entries
  std::vector<float> u_, v_;  // scratch: the band's events in the segment's frame
  std::vector<char> bins_;    // scratch: per 1-px bin beyond each end, whether it holds an event of interest
};

}  // namespace evldt
