#pragma once
// Whether a block's line is a piece of a curve: the events beyond its ends.
//
// A block holds too short a stretch of an edge to tell an arc from a line: a circle of radius 5 b
// is 0.03 b off the chord across one block, well inside the inlier band, so arcs are detected and
// tracked as lines. Beyond the block the arc bends away: over a span of 3 b it is 0.2 b off. The
// test looks at the lattice events of a band around the segment extended by b at each end, and
// calls the segment bent when
//   - the edge does not run on straight in the far half of either extension (parallel edges and a
//     corner's other edge may lie in the band too: an edge that continues on the segment's line is
//     no arc), and the events there lie off to the same side beyond both ends (these two looks
//     decide most segments from a few blocks, before any fit);
//   - v = a + t u + c u^2 (u along the segment, v across), fitted robustly to the band, has its
//     middle far enough off the chord (c) and does not rise at one end alone (t: the column of a
//     corner's other edge);
//   - events follow that curve beyond both ends.
// The thresholds were tuned on circle-board, monitor-hd and tag-board (docs/whole-lines.md).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "evldt/lines/geometry.hpp"
#include "evldt/scarf/scarf_lattice.hpp"

namespace evldt {

class BendTest {
 public:
  /// max_bend_ratio: ScoreParams::max_bend_ratio (0: never bent).
  BendTest(const LatticeGeometry& geometry, float max_bend_ratio);

  /// True when `segment` is a stretch of an edge that bends away to one side beyond both of its ends.
  bool bent(const ScarfLattice& lattice, const Segment& segment);

 private:
  struct Frame {  // the segment's: v across it is (p - centre) . normal
    Point2 centre, normal;
    float length;
  };
  /// Whether the edge runs on straight in the far half of the extension beyond `end`; `offsets`
  /// receives the offsets across the segment of the band's events there.
  bool runs_straight(const ScarfLattice& lattice, const Frame& frame, Point2 end, Point2 outward,
                     std::vector<float>& offsets);
  /// Along one axis, the block (0 .. blocks - 1) whose region's centre is nearest `coordinate`.
  [[nodiscard]] int nearest_region(float coordinate, int blocks) const;
  /// The sign (-1, 0, 1) of the median of `offsets`, 0 when empty.
  static int median_sign(const std::vector<float>& offsets);
  /// The median of `offsets` (reordered), 0 when empty.
  static float median(std::vector<float>& offsets);
  bool followed_beyond_both_ends(const Eigen::Vector3d& curve, float length, float half_span);

  LatticeGeometry geometry_;
  float min_bend_px_;
  std::vector<int> cells_;    // scratch: the blocks along the extended segment
  std::vector<float> u_, v_;  // scratch: the band's events in the segment's frame (v_ first: the offsets beyond q0)
  std::vector<float> after_;  // scratch: the offsets beyond q1
  // Scratch per entry of one block: its place in the segment's frame and what it counts for.
  std::vector<float> entry_along_, entry_offsets_;
  std::vector<std::int32_t> entry_keys_;
};

}  // namespace evldt
