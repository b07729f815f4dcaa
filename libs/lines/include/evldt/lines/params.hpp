#pragma once
// Parameters of the method: the lattice, the fitting score, tracking and whole lines
// (docs/design.md). The runtime adds its schedule, filters and calibration (evldt/pipeline/pipeline_config.hpp).

#include <cstdint>

#include "evldt/events/event.hpp"
#include "evldt/lines/normal_motion.hpp"

namespace evldt {

/// What the active-inlier count of a multi-block tracking score is divided by (docs/design.md, section 9).
enum class EffectiveRatioNorm : std::uint8_t {
  Block,  ///< N: long lines spanning k blocks can score r_e up to k
  Union,  ///< k * N: r_e stays in [0, 1] whatever the number of blocks
};

struct LatticeParams {
  SensorSize sensor{640, 480};
  int block_size = 14;  ///< b
  double alpha = 1.0;   ///< ring capacity N = floor(alpha * b * b / 2)
};

struct ScoreParams {
  float fit_threshold = 0.2f;          ///< f_th: a line is kept while its fitting score f > f_th
  float inlier_distance_ratio = 0.2f;  ///< d_max = ratio * b
  int fit_iterations = 3;              ///< robust (Fair-weighted) reweighting rounds after the first PCA fit
  /// of b (at least 2 px): a block's line is not detected where the events run on beyond both of its
  /// ends and bend away to one side by this much over the span (an arc: bend_test.hpp). 0: off.
  float max_bend_ratio = 0.1f;
  /// of N: a block whose fit failed is fitted again only once this share of N new active entries
  /// came in (floor(share * N); 0: at any change). Chosen on the built-in scenes (docs/accuracy.md).
  float retry_share = 0.15f;
};

/// A new detection takes over the id of a line released nearby a moment before, so an id lasts
/// through a short loss of its edge and through ownership hand-over (docs/design.md, section 4).
struct ReassociationParams {
  Timestamp window_us = 100'000;  ///< since the released line's last good track; 0: never
  float max_angle_deg = 10.0f;
  float max_offset_ratio = 0.5f;  ///< of b: the new segment's centre from the released line
};

struct TrackParams {
  float perturbation_px = 2.5f;  ///< dq
  /// Event time a line may go without a good track before it is released: 30 ms keeps every scene's
  /// F@1% at or above that of the former 10 rounds (20 ms); 80 ms gains slow clean scenes 0.02 more
  /// and costs the dark one as much (docs/accuracy.md, tracks that last).
  Timestamp bad_track_patience_us = 30'000;
  EffectiveRatioNorm multi_block_norm = EffectiveRatioNorm::Block;
  ReassociationParams reassociation;
  MotionParams motion;
};

/// Joining block segments into whole lines (whole_lines.hpp). Chosen on boxes-10s: tighter joins
/// (8 degrees, 0.3 b, 1 b) split true lines and halved IDF1 (0.115 against 0.315). The angle is wide
/// because the block segments along an edge that moves across itself tilt by up to 15-20 degrees
/// either way (a fit across its band of events): at 12 degrees none of them joined.
struct WholeLineParams {
  float max_angle_deg = 20.0f;    ///< a segment joins a line whose direction is this close to its own
  float max_offset_ratio = 0.6f;  ///< of b: both its ends within this of the line
  float max_gap_ratio = 2.0f;     ///< of b: and it overlaps the line's extent or is at most this far from it
  /// A segment that was part of the line at the last step stays within this direction of it (and
  /// twice the offset and gap bounds: a line does not split for a step's wobble); also the bound of a
  /// waiting line looking for its edge, and of a second line along a published one.
  float loose_angle_deg = 24.0f;
  Timestamp keep_id_us =
      1'000'000;  ///< a line without segments for this long ends; before, it may take segments up again
  /// An end its segments no longer reach stays this long: a block segment at the end of an edge comes
  /// and goes with the events there, the edge does not.
  Timestamp end_memory_us = 100'000;
  float min_length_ratio = 3.0f;  ///< of b: a line is published once it is this long (then while it lasts)
  /// of b: two published lines whose ends both lie this close to where they cross meet there (a corner:
  /// the block at a corner holds two edges and fits neither, so both fall short of it). 0: off.
  float corner_reach_ratio = 2.0f;
  float corner_min_angle_deg = 30.0f;  ///< lines closer in direction than this do not make a corner
  /// of b: a line takes in a new segment across a longer gap only where the lattice holds events
  /// along the gap (when the tracker is given the lattice): half or more of its pixels with an event
  /// within 1.5 px. Collinear edges of separate objects are apart by a gap without events; one edge
  /// whose segment is missing somewhere is not.
  float max_unsupported_gap_ratio = 0.5f;
  /// Where a line would reach beyond its segments, it does so only where events hold that stretch,
  /// with a tolerance that grows from 1.5 px by this many px per px beyond the segments (the line's
  /// direction is known only so well): an end grows to a corner only if the stretch is held as a gap
  /// must be (two edges that only nearly meet make no corner; ends past a corner are still drawn back
  /// to it), and an end remembered for end_memory_us is kept only as far as the events along it go
  /// on (an edge's end that the events left is not kept). Chosen over 0 and 0.05 on the built-in
  /// scenes (docs/whole-lines.md).
  float extension_spread = 0.1f;
  /// of b: a published line's end is drawn out along the events beyond its segments up to this far
  /// (the segments fall short of an edge's end where the block there holds a corner, or is not yet
  /// detected): as far as a line of events goes on that is no wider band (of noise or a trail), up
  /// to where it comes near another published line. 0: off.
  float event_reach_ratio = 2.0f;
};

}  // namespace evldt
