#pragma once
// How much of the whole lines the block segments of the same step back. A whole line
// joins segments and may bridge the gaps between them and reach on to a corner; its length within
// a small distance of some segment of its step is what the lattice's events support directly.
// A line that bridges the gap between two separate edges, or cuts across a pattern to a corner,
// shows as unsupported length. Needs no ground truth, so it scores real recordings too.

#include <cstdint>
#include <span>
#include <vector>

#include "evldt/lines/geometry.hpp"

namespace evldt {

struct SupportSummary {
  std::uint64_t steps = 0;
  std::uint64_t lines = 0;       ///< whole lines over all steps
  double length_px = 0;          ///< their length
  double supported_share = 0;    ///< of that length, within the distance of a segment (NaN without lines)
  std::uint64_t weak_lines = 0;  ///< lines supported along less than the weak share of their length
  double weak_share = 0;         ///< weak_lines / lines (NaN without lines)
};

class WholeLineSupport {
 public:
  /// `distance_px`: how near a segment a point of a whole line must lie; `weak_below`: a line with a
  /// smaller supported share of its length is weak. Throws std::invalid_argument for a negative
  /// distance or a share outside 0..1.
  explicit WholeLineSupport(float distance_px = 2.0f, float weak_below = 0.6f);
  /// One step: the whole lines and the block segments they were joined from.
  void add_step(std::span<const Segment> whole_lines, std::span<const Segment> segments);
  [[nodiscard]] SupportSummary summary() const;

 private:
  float distance_px_;
  float weak_below_;
  SupportSummary totals_;
  double supported_px_ = 0;
  std::vector<std::uint32_t> near_;  // scratch: the segments whose box is near the line's
};

}  // namespace evldt
