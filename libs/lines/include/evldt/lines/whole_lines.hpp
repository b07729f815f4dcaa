#pragma once
// Whole lines: block segments that lie along one straight edge, joined into a line that is tracked
// as one object over time, with its own id. Runs on a snapshot of the live
// segments at each output step, after tracking; deterministic for a given sequence of calls.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/lines/event_pixels.hpp"
#include "evldt/lines/geometry.hpp"
#include "evldt/lines/line_map.hpp"
#include "evldt/lines/point_grid.hpp"
#include "evldt/scarf/scarf_lattice.hpp"

namespace evldt {

class WholeLineTracker {
 public:
  /// block_size: the lattice's b, the unit of the distances in `params`. Ids start at first_id (a
  /// service folds its start time in, as for segment ids).
  explicit WholeLineTracker(int block_size, const WholeLineParams& params = {}, std::uint64_t first_id = 1);

  /// One step. Each line tracked so far, the first published first, takes back the segments it held
  /// that still lie along it, where its velocity has taken it since it last held segments (for at
  /// most 20 ms), and grows along its edge over free segments (taking over a younger
  /// line's segments where they fit, which merges the two). A published line that finds none waits
  /// keep_id_us under its last geometry and may take segments up again, from those left by the
  /// published lines that took theirs back; one never published ends.
  /// The segments left start new lines. An end its segments no longer reach stays where it was for
  /// end_memory_us. Steps must come in time order. With `events` (the lattice the segments were
  /// tracked on), a line reaches beyond its segments only where the lattice holds events along the
  /// stretch: across a gap longer than max_unsupported_gap_ratio * b to a new segment, to a corner;
  /// towards a remembered end only as far as the events along it go on; without, on geometry alone.
  /// With it, a published line's ends are also drawn out along the events beyond them
  /// (event_reach_ratio; what is published only, the line is tracked on its segments).
  void update(Timestamp t, std::span<const TrackedLine> segments, const ScarfLattice* events = nullptr);

  /// The lines of the last step that are published: those holding segments now that reached
  /// min_length_ratio * b at some step. Ids are given on publication, so a line never published uses none.
  [[nodiscard]] const std::vector<WholeLine>& lines() const { return published_; }
  /// Time of the last update (0 before the first).
  [[nodiscard]] Timestamp last_time() const { return last_t_; }
  /// Distinct ids published so far.
  [[nodiscard]] std::uint64_t created() const { return next_id_ - first_id_; }

 private:
  /// An infinite line through `point` along unit `direction`, and an extent [t_min, t_max] along it.
  struct LineModel {
    Point2 point = Point2::Zero();
    Point2 direction = Point2::UnitX();
    float t_min = 0, t_max = 0;
    [[nodiscard]] Segment extent() const { return {point + t_min * direction, point + t_max * direction}; }
  };
  struct Track {
    std::uint64_t key = 0;  ///< internal, for segment ownership; every track has one
    std::uint64_t id = 0;   ///< public, 0 until published
    LineModel model;
    Timestamp first_seen_us = 0;
    Timestamp last_seen_us = 0;              ///< last step with segments
    std::array<Timestamp, 2> end_seen_us{};  ///< last step the segments reached the t_min / t_max end
    std::uint32_t segments = 0;
    float velocity = 0, velocity_std = 0;  ///< across the model's normal (-direction.y, direction.x), px/s
  };
  /// A line being grown this step: the length-weighted fit through its members' ends.
  struct Cluster {
    LineModel model;
    double weight = 0, sum_x = 0, sum_y = 0, sum_xx = 0, sum_xy = 0, sum_yy = 0;
    std::size_t first_member = 0;
  };

  /// Whether `segment` lies along `line`: both ends' offsets within the bound times `relax` and its
  /// direction within max_angle_deg (loose_angle_deg where relax > 1), the gap to its extent within
  /// the gap bound times `gap_relax` (2 and 2 for a segment
  /// that was part of this line at the last step: hysteresis, a line does not split for a step's
  /// wobble; 2 and 1 where a waiting line looks for its edge, which may have moved across itself
  /// while it waited, but a segment farther along than a join reaches is another edge's).
  [[nodiscard]] bool fits(const LineModel& line, const Segment& segment, float relax, float gap_relax) const;
  /// Whether the stretch from `from` to `to` may be bridged: it is short, or no lattice was given,
  /// or half or more of its pixels have an event of the lattice within 1.5 px + spread * (distance
  /// from `from`).
  [[nodiscard]] bool bridged(Point2 from, Point2 to, float spread = 0) const;
  /// How far from `from` towards `to` the events go on along the stretch: to the last pixel farther
  /// from `from` than its tolerance with an event within it (1.5 px + spread * the distance), passing
  /// over runs of up to b without one; all of it once what is left after such a pixel is at most b
  /// long; 0 if there is none. All of it without a lattice.
  [[nodiscard]] float held_reach(Point2 from, Point2 to, float spread) const;
  /// The key of the track a segment (by id) belonged to at the last step, or 0.
  [[nodiscard]] std::uint64_t former_track_of(std::uint64_t segment_id) const;
  /// This step's segments indexed: their ends in a grid, the track each belonged to, longest first.
  void index_segments(std::span<const TrackedLine> segments);
  /// Each track, the first published first, takes back its former segments or finds its edge along
  /// where it is expected, and grows; then new lines grow from the segments left. Returns the first
  /// new line's cluster.
  std::size_t associate(Timestamp t, std::span<const TrackedLine> segments);
  /// Track k's cluster this step: its former segments taken back (take_back), else a free one found
  /// along its expected geometry (look_along), then grown; none leaves it waiting.
  void follow_track(std::size_t k, Timestamp t, bool take_back, bool look_along, std::span<const TrackedLine> segments);
  [[nodiscard]] std::uint32_t members_of(std::size_t cluster) const;
  /// The tracks of the next step (followed ones moved to their clusters, waiting ones kept, ended
  /// ones dropped, new ones) and the track of each segment id.
  void carry_tracks_over(Timestamp t, std::size_t first_new_cluster, std::span<const TrackedLine> segments);
  /// The lines published at this step (an id for each new one long enough and not shadowed), and
  /// the tracks in publishing order.
  void publish(Timestamp t);
  /// Adds segment `s` as a member of the last cluster and refits its direction and extent.
  void add_member(Cluster& cluster, std::uint32_t s, std::span<const TrackedLine> segments);
  /// Adds to the last cluster every free segment that fits it, searching the grid cells around its
  /// members' ends. former_track: the key whose former segments fit loosely (0: none).
  void grow(Cluster& cluster, std::uint64_t former_track, std::span<const TrackedLine> segments);
  /// The first free segment (in grid order) that fits `line` within the loose angle, twice the offset
  /// bound and the gap bound (fits()), searched along its extent, or npos.
  [[nodiscard]] std::size_t first_fit_along(const LineModel& line, std::span<const TrackedLine> segments) const;
  /// Whether a line published at this step lies along `segment` (within the loose bounds) and covers
  /// half of it or more: a second line on its edge waits until it merges into it or outlives it.
  [[nodiscard]] bool shadowed(const Segment& segment) const;
  /// Draws the ends of published lines out along the events beyond them (WholeLineParams::event_reach_ratio),
  /// each from the lines as they were before any end moved.
  void reach_along_events();
  /// How far the events hold a line going on from `from` along unit `direction`, up to `max_length`:
  /// to the last pixel by which the pixels held so far are kReachMinShare or more of those passed, a
  /// pixel held where an event lies within kReachEventRadius of it but not also on both sides of it
  /// kReachSideOffset off the line (a band of noise or of a trail, no edge); the reach ends after a
  /// run of kReachMaxRun without a held pixel.
  [[nodiscard]] float events_reach(Point2 from, Point2 direction, float max_length) const;
  /// Moves the ends of published lines that make a corner to the corner (WholeLineParams::corner_*).
  void meet_at_corners();
  /// Where `track`'s line is expected at time t: its last geometry moved across itself by its
  /// velocity for the time since it last held segments (at most kMaxPredictionUs).
  [[nodiscard]] LineModel expected_model(const Track& track, Timestamp t) const;
  /// The motion of cluster c from its members': their velocities along its normal, weighted by the
  /// inverse of their variances; the deviation of that mean, widened by the members' disagreement.
  [[nodiscard]] std::pair<float, float> cluster_motion(std::size_t c, std::uint32_t members,
                                                       std::span<const TrackedLine> segments) const;
  /// `track` followed by cluster `c`: new geometry, remembered ends, times.
  void continue_track(Track& track, const Cluster& cluster, std::uint32_t members, Timestamp t) const;

  float block_size_;
  WholeLineParams params_;
  const ScarfLattice* events_ = nullptr;  ///< of the current update(), or none
  mutable EventPixels event_pixels_;      ///< of events_: a cache, filled as the queries come
  float cell_size_;                       ///< of the grid of segment ends
  float min_cos_angle_;
  float loose_cos_angle_;  ///< of WholeLineParams::loose_angle_deg
  std::uint64_t first_id_;
  std::uint64_t next_id_;
  std::uint64_t next_key_ = 1;
  bool stepped_ = false;
  Timestamp last_t_ = 0;
  std::vector<Track> tracks_;  ///< published ones first, in the order they were published; then by age
  std::vector<WholeLine> published_;

  // Scratch, kept between calls.
  std::vector<Point2> ends_;  ///< segment i's ends at 2i, 2i + 1 (published lines' in meet_at_corners)
  PointGrid end_grid_;        ///< of the segments' ends
  PointGrid corner_grid_;     ///< of the published lines' ends
  std::vector<std::uint32_t> order_, members_, cluster_of_segment_;
  std::vector<std::uint64_t> former_track_of_segment_;  ///< former_track_of() each segment (by index) of this step
  std::vector<std::pair<std::uint64_t, std::uint32_t>>
      segments_of_former_track_;  ///< (former track key, segment index), by key then length
  std::vector<Cluster> clusters_;
  std::vector<std::size_t> cluster_of_track_;  ///< index into clusters_ of each of tracks_, or npos
  std::vector<Track> next_tracks_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>>
      track_of_segment_id_;  ///< (segment id, track key) of the last step, sorted
  std::vector<std::pair<std::uint64_t, std::uint64_t>> next_track_of_segment_id_;
  struct Corner {
    float cost = 0;  ///< the two ends' distances to the corner
    std::uint32_t end_a = 0, end_b = 0;
    Point2 at = Point2::Zero();
  };
  std::vector<Corner> corners_;
  std::vector<std::uint8_t> end_moved_;
  std::vector<Point2> line_samples_;  ///< points along the published lines, for reach_along_events
  std::vector<std::uint32_t> line_of_sample_;
  PointGrid line_grid_;  ///< of line_samples_
  std::vector<std::uint32_t> nearby_lines_;
  std::vector<Segment> reached_;
};

}  // namespace evldt
