#pragma once
// Whole lines: block segments that lie along one straight edge, joined into a line with its own
// id, which it keeps while its segments come and go (issues 15 and 16). Runs on a snapshot of the
// live segments at each output step, after tracking; deterministic for a given sequence of calls.

#include <cstdint>
#include <span>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/lines/geometry.hpp"
#include "evldt/lines/line_map.hpp"

namespace evldt {

struct WholeLine {
  std::uint64_t id = 0;
  Segment segment;              ///< the fitted line over the extent of its segments
  std::uint32_t segments = 0;   ///< block segments joined into it
  Timestamp first_seen_us = 0;
  Timestamp last_seen_us = 0;
};

class WholeLineTracker {
 public:
  /// block_size: the lattice's b, the unit of the distances in `params`. Ids start at first_id (a
  /// service folds its start time in, as for segment ids).
  explicit WholeLineTracker(int block_size, const WholeLineParams& params = {}, std::uint64_t first_id = 1);

  /// Joins the segments of one step into whole lines and carries ids over from the previous step:
  /// a line takes the id of the earlier line that most of its segments' length belonged to (each id
  /// once), else of a line that ended within keep_id_us along the same stretch of edge, else a new
  /// id. Steps must come in time order.
  void update(Timestamp t, std::span<const TrackedLine> segments);

  [[nodiscard]] const std::vector<WholeLine>& lines() const { return lines_; }
  /// Time of the last update (0 before the first).
  [[nodiscard]] Timestamp last_time() const { return last_t_; }
  /// Distinct ids given so far.
  [[nodiscard]] std::uint64_t created() const { return next_id_ - first_id_; }

 private:
  /// A line being grown: the length-weighted fit through its members' ends.
  struct Cluster {
    Point2 point = Point2::Zero();  ///< centroid of the members' ends, on the fitted line
    Point2 direction = Point2::UnitX();
    float t_min = 0, t_max = 0;  ///< extent along direction from point
    double weight = 0, sum_x = 0, sum_y = 0, sum_xx = 0, sum_xy = 0, sum_yy = 0;
  };
  [[nodiscard]] std::int64_t cell_of(const Point2& p) const;
  /// together_before: the segment and the cluster's seed belonged to one line at the last step;
  /// such a pair joins within twice the angle, offset and gap (hysteresis: a line does not split
  /// for a step's wobble).
  [[nodiscard]] bool fits(const Cluster& cluster, const Segment& segment, bool together_before) const;
  /// The whole-line id a segment belonged to at the last step, or 0.
  [[nodiscard]] std::uint64_t previous_owner(std::uint64_t segment_id) const;
  /// Adds a member's ends to the moments and refits direction and extent over members [first, end).
  void add_member(Cluster& cluster, std::size_t first, std::span<const TrackedLine> segments) const;
  /// The index of the earlier line, ended within keep_id_us, that `cluster` continues, or npos.
  [[nodiscard]] std::size_t find_ended(const Cluster& cluster, Timestamp t) const;

  float block_size_;
  WholeLineParams params_;
  float cell_size_;  ///< of the grid of segment ends
  float min_cos_angle_;
  float loose_cos_angle_;
  std::uint64_t first_id_;
  std::uint64_t next_id_;
  bool stepped_ = false;
  Timestamp last_t_ = 0;
  std::vector<WholeLine> lines_;
  std::vector<WholeLine> ended_;  ///< lines that ended within keep_id_us

  // Scratch, kept between calls.
  std::vector<std::pair<std::int64_t, std::uint32_t>> grid_;  ///< (cell of a segment end, segment), sorted
  std::vector<std::uint32_t> order_, members_, cluster_of_segment_;
  std::vector<Cluster> clusters_;
  std::vector<std::size_t> cluster_start_;  ///< members of cluster c: members_[start[c], start[c + 1])
  std::vector<std::uint64_t> id_of_cluster_;
  std::vector<Timestamp> first_seen_of_cluster_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> owner_;  ///< (segment id, whole id) of the last step, sorted
  std::vector<std::pair<std::uint64_t, std::uint64_t>> next_owner_;
  std::vector<std::pair<std::uint64_t, std::size_t>> line_of_id_;  ///< (id, index into lines_), sorted
  struct Vote {
    std::size_t cluster = 0;
    std::uint64_t id = 0;
    double length = 0;
  };
  std::vector<Vote> votes_;
};

/// Whole lines as rows of the segment format (segment_csv.hpp): score = the number of block segments
/// joined, status good, admin block -1.
void as_tracked_lines(std::span<const WholeLine> lines, std::vector<TrackedLine>& out);

}  // namespace evldt
