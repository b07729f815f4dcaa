#pragma once
// The lines alive in the lattice and which block administers each (docs/design.md, sections 4 and 5): line ids,
// block statuses, ownership transfer and detection suppression.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "evldt/lines/geometry.hpp"
#include "evldt/lines/line_types.hpp"
#include "evldt/lines/params.hpp"
#include "evldt/scarf/scarf_lattice.hpp"

namespace evldt {

enum class BlockStatus : std::uint8_t {
  NoDetect,           ///< free: detection may create a line here
  ProhibitDetection,  ///< skipped by the next detection round (a tracked line is too close)
  Owned,              ///< administers a line
};

/// Why a line ended; the pipeline's statistics count each.
enum class ReleaseReason : std::uint8_t { TooFewPoints, TooShort, LeftSensor, BadTracks, LostOwnership };
inline constexpr int kReleaseReasonCount = 5;
std::string_view reason_name(ReleaseReason reason);

/// Lifetimes (last good track - first seen) of a set of lines.
struct LifetimeStats {
  std::uint64_t count = 0;
  double sum_us = 0;
  Timestamp max_us = 0;
  void add(Timestamp lifetime_us) {
    ++count;
    sum_us += static_cast<double>(lifetime_us);
    if (lifetime_us > max_us) max_us = lifetime_us;
  }
  /// Takes back an add() whose line lives on under a new one (its lifetime will be longer, so the
  /// maximum stays right).
  void take_back(Timestamp lifetime_us) {
    --count;
    sum_us -= static_cast<double>(lifetime_us);
  }
  [[nodiscard]] double mean_us() const { return count ? sum_us / static_cast<double>(count) : 0.0; }
};

class LineMap {
 public:
  explicit LineMap(const LatticeGeometry& geometry, const ReassociationParams& reassociation = {},
                   const MotionParams& motion = {});

  [[nodiscard]] const std::vector<TrackedLine>& lines() const { return lines_; }
  /// The lines, to change in place (their number changes only through add and release).
  [[nodiscard]] std::span<TrackedLine> lines() { return lines_; }
  /// The tracker's bookkeeping for lines()[index]: the newest version of the line's blocks at its
  /// last pass, if that pass left the segment where it was; 0 otherwise. While its blocks keep that
  /// version a pass would repeat itself exactly, so the tracker reuses its score.
  [[nodiscard]] std::uint64_t& settled_version(std::size_t index) { return settled_[index]; }
  /// Where the middle of lines()[index]'s event band lay at its last tracking pass (a point, off
  /// the segment along its normal by the inliers' mean offset): finer than the segment's own place,
  /// whose ends move in steps of dq.
  [[nodiscard]] Point2& band_centre(std::size_t index) { return band_centre_[index]; }
  /// Observes where each line's band is after a tracking round at `now` (of those with a good
  /// track: a bad one's place says nothing of its edge) and sets its normal_velocity and
  /// normal_velocity_std.
  void observe_motion(Timestamp now);
  [[nodiscard]] BlockStatus block_status(int block) const { return status_[block]; }
  void set_block_status(int block, BlockStatus status);

  /// Creates a line administered by a free block; returns its id. The line takes over the id,
  /// first-seen time and velocity of a line released from this block or a neighbour within the
  /// reassociation window when it lies along it (angle and offset within bounds; of several, the
  /// nearest), else it gets a new id and the velocity of a live line it lies along in this block or
  /// a neighbour (neighbour_motion), if any.
  std::uint64_t add(const Segment& segment, float score, int admin_block, Timestamp now);
  /// Removes the line at `index` (swap-remove: the last line takes its place) and frees its block.
  void release(std::size_t index, ReleaseReason reason);

  /// Manager, after a tracking round: hand each line to the block its centre moved into (resolving a
  /// collision in favour of the better score, releasing the other), then mark the admin's row and
  /// column neighbours within `suppress_ratio * b` of the line centre ProhibitDetection.
  void manage(float suppress_ratio);

  [[nodiscard]] std::uint64_t released(ReleaseReason reason) const { return released_[static_cast<int>(reason)]; }
  /// Lifetimes of the lines released so far (add the live ones for a run's total).
  [[nodiscard]] const LifetimeStats& released_lifetimes() const { return released_lifetimes_; }
  [[nodiscard]] std::uint64_t created() const { return next_id_ - first_id_; }
  /// Lines that took over a released line's id.
  [[nodiscard]] std::uint64_t reassociated() const { return reassociated_; }
  /// Ids start here; a per-process epoch can be folded in by the caller (services restart).
  void set_first_id(std::uint64_t first);
  void clear();

 private:
  /// A line released a moment ago, remembered by the block that administered it.
  struct ReleasedLine {
    bool present = false;
    std::uint64_t id = 0;
    Segment segment;
    Timestamp first_seen_us = 0;
    Timestamp last_good_us = 0;
    NormalMotion motion;
  };
  void transfer_ownership();
  void suppress_detection(float suppress_ratio);
  /// How far `centre` lies from `line`, if a segment along unit `direction` through it lies along
  /// the line within the reassociation angle; infinity if not.
  [[nodiscard]] float offset_along(const Segment& line, Point2 direction, Point2 centre) const;
  /// The motion of a live line in `block` or a neighbour that a new segment there lies along (as
  /// find_released asks), the nearest; or nullptr.
  [[nodiscard]] const NormalMotion* neighbour_motion(const Segment& segment, int block) const;
  /// The remembered line a new segment in `block` continues, or nullptr.
  ReleasedLine* find_released(const Segment& segment, int block, Timestamp now);

  LatticeGeometry geometry_;
  ReassociationParams reassociation_;
  MotionParams motion_params_;
  float min_cos_angle_ = 1;
  std::vector<ReleasedLine> released_by_block_;  ///< per block: the last line released from it
  std::uint64_t reassociated_ = 0;
  std::vector<BlockStatus> status_;
  std::vector<std::int32_t> owner_;  ///< per block: index into lines_ of the line it administers, or -1
  std::vector<TrackedLine> lines_;
  std::vector<std::uint64_t> settled_;  ///< per line, settled_version()
  std::vector<NormalMotion> motion_;    ///< per line: the estimate of its motion across itself
  std::vector<Point2> band_centre_;     ///< per line, band_centre()
  std::uint64_t first_id_ = 1;
  std::uint64_t next_id_ = 1;
  std::uint64_t released_[kReleaseReasonCount] = {};
  LifetimeStats released_lifetimes_;
};

}  // namespace evldt
