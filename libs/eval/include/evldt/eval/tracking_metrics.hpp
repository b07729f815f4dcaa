#pragma once
// Tracking metrics for line segments, after CLEAR-MOT and IDF1, with ground-truth lines as the
// objects and predicted ids as the hypotheses. A predicted segment matches a true line at a step when
// at least min_overlap of its length lies within the tolerance of that line's visible pieces (of
// several such lines, the one covering most of it). Lengths are sampled every kOverlapSamplePx.

#include <cstdint>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/lines/geometry.hpp"

namespace evldt {

/// Largest distance between the samples that measure how much of a segment lies near a line, in px.
inline constexpr double kOverlapSamplePx = 1.0;
/// The share of a predicted segment's length that must lie within the tolerance of a true line.
inline constexpr double kDefaultMinOverlap = 0.5;

/// Which predicted id stood for a true line at one step (matched = false: none matched it).
struct LineOwnerStep {
  Timestamp t_us = 0;
  bool matched = false;
  std::uint64_t id = 0;
};

/// One ground-truth line over the run.
struct GroundTruthLineTrack {
  std::uint64_t gt_id = 0;
  std::uint64_t visible_steps = 0;
  std::uint64_t matched_steps = 0;  ///< steps at which at least one predicted segment matched it
  std::uint64_t distinct_ids = 0;   ///< predicted ids that matched it at some step (fragmentation)
  std::uint64_t id_switches = 0;    ///< times its representative id changed
  /// Every visible step. The representative is the id that represented it before if that id still
  /// matches, else the matching id covering most of it (ties: the lower id), as CLEAR-MOT keeps a
  /// correspondence while it holds. A step that nothing matches leaves the representative as it was.
  std::vector<LineOwnerStep> owners;
};

/// What became of the id that stood for a true line when another took its place, at the step of the
/// switch: the causes of identity loss, each switch counted under the first that holds.
struct IdSwitchCauses {
  std::uint64_t to_other_edge = 0;  ///< the old id is published and now matches another true line
  std::uint64_t off_edge = 0;       ///< the old id is published and matches no true line (it drifted or lags)
  std::uint64_t returned = 0;       ///< the old id is not published at this step but comes back later
  std::uint64_t redetected = 0;  ///< the old id is gone for good and the new one first appeared after it was last seen
  std::uint64_t taken_over = 0;  ///< the old id is gone for good and the new one was already published before that
  /// Of all switches: those after one or more steps at which nothing matched the true line.
  std::uint64_t after_gap = 0;
};

struct TrackingSummary {
  std::uint64_t ground_truth_lines = 0;
  std::uint64_t lines_never_matched = 0;
  /// Matched line-steps over visible line-steps: how much of the true lines' lives is covered.
  double coverage = 0;
  /// Mean distinct ids per line over the lines matched at least once (1 = one id for a line's life).
  double ids_per_line = 0;
  std::uint64_t id_switches = 0;
  IdSwitchCauses switch_causes;
  /// IDF1 over lengths: the global one-to-one assignment of predicted ids to true lines that
  /// maximises the matched length summed over steps (id_true_positive_px); id precision divides it
  /// by all predicted length, id recall by all true length. NaN where a denominator is 0.
  double id_precision = 0;
  double id_recall = 0;
  double idf1 = 0;
  double id_true_positive_px = 0;
  double predicted_px = 0;
  double ground_truth_px = 0;
  /// Length matched to a true line at some step by an id the assignment did not give that line:
  /// identity lost on length that was found (IDF1 would reach 2 (id_true_positive_px + this) /
  /// (predicted_px + ground_truth_px) with one id per line).
  double unassigned_matched_px = 0;
  /// Motion, over every step at which a predicted line with a velocity matched a true line whose
  /// velocity is known: the median of |predicted - true| normal velocity (px/s), and of that over the
  /// true speed where the true line moves at kMinRelativeSpeed or more. NaN without such pairs.
  std::uint64_t velocity_pairs = 0;
  double velocity_error_median = 0;
  double velocity_relative_median = 0;
};

/// True speeds below this (px/s) are left out of the relative velocity error: there the error is
/// noise over almost nothing.
inline constexpr double kMinRelativeSpeed = 10.0;

class TrackingEvaluator {
 public:
  /// Segments are measured on the sensor only (clipped to it, as the heat map draws them). Throws
  /// std::invalid_argument for an invalid sensor, unless tolerance_px >= 0 and min_overlap is in (0, 1].
  TrackingEvaluator(SensorSize sensor, double tolerance_px, double min_overlap = kDefaultMinOverlap);

  /// One step: the prediction in force and the true lines' visible pieces (several pieces may share a
  /// line id). Each id span must be as long as its segment span (else std::invalid_argument). Steps
  /// must come in time order.
  /// With velocities: each predicted segment's normal velocity (along its own normal, normal_motion.hpp)
  /// and each true piece's (NaN: unknown), both empty when not known; a pair of them is compared
  /// wherever a segment matches a line.
  void add_step(Timestamp t, std::span<const std::uint64_t> predicted_ids, std::span<const Segment> predicted,
                std::span<const std::uint64_t> truth_ids, std::span<const Segment> truth,
                std::span<const float> predicted_velocities = {}, std::span<const float> truth_velocities = {});

  /// Solves the id assignment over everything added so far.
  [[nodiscard]] TrackingSummary summary() const;
  /// One entry per true line seen, in order of first appearance.
  [[nodiscard]] const std::vector<GroundTruthLineTrack>& lines() const { return lines_; }
  [[nodiscard]] double tolerance_px() const { return tolerance_px_; }
  [[nodiscard]] double min_overlap() const { return min_overlap_; }

 private:
  struct Match {
    std::size_t line = 0;
    std::uint64_t id = 0;
    double overlap_px = 0;
  };
  /// A change of a true line's representative, classified in summary().
  struct Switch {
    std::size_t line = 0;
    std::size_t step = 0;
    std::uint64_t old_id = 0, new_id = 0;
    bool after_gap = false;
  };
  /// The first and last step a predicted id was published at.
  struct IdSightings {
    std::size_t first_step = 0, last_step = 0;
  };
  [[nodiscard]] IdSwitchCauses classify_switches() const;
  /// The length of `segment`'s part on the sensor within the tolerance of each line, into
  /// overlap_by_line_ (indexed like step_lines_); returns the length of that part.
  double measure_overlaps(const Segment& segment, std::span<const Segment> truth);
  std::size_t line_index(std::uint64_t gt_id);
  std::size_t predicted_index(std::uint64_t id);

  SensorSize sensor_;
  double tolerance_px_;
  double min_overlap_;
  std::vector<GroundTruthLineTrack> lines_;
  std::vector<std::unordered_set<std::uint64_t>> ids_of_line_;
  std::vector<LineOwnerStep> last_owner_;  ///< per line: its representative when last matched
  std::unordered_map<std::uint64_t, std::size_t> line_of_gt_id_;
  std::unordered_map<std::uint64_t, std::size_t> index_of_predicted_id_;
  /// Matched length summed over steps per (predicted index, line index), key = predicted << 32 | line.
  std::unordered_map<std::uint64_t, double> pair_overlap_px_;
  double predicted_px_ = 0;
  double ground_truth_px_ = 0;
  std::size_t steps_ = 0;
  std::vector<Switch> switches_;
  std::vector<double> velocity_errors_, relative_velocity_errors_;
  std::unordered_map<std::uint64_t, IdSightings> sightings_;
  /// Per step, every published id and the line it matched (npos: none), sorted by id.
  std::vector<std::vector<std::pair<std::uint64_t, std::size_t>>> ids_at_step_;

  // Per-step scratch.
  std::vector<std::size_t> line_of_piece_;  ///< index into lines_ of each truth piece
  std::vector<std::size_t> step_lines_;     ///< distinct lines of this step
  std::vector<std::size_t> first_piece_;    ///< per step line: its first truth piece
  std::vector<std::size_t> slot_of_line_;   ///< position in step_lines_ of each line seen (or npos)
  std::vector<double> overlap_by_line_;
  std::vector<std::size_t> hit_stamp_;   ///< per step line: the last sample that counted for it
  std::vector<std::size_t> candidates_;  ///< truth pieces near the segment being measured
  std::vector<Match> matches_;
  bool stepped_ = false;
  Timestamp last_t_ = 0;
};

}  // namespace evldt
