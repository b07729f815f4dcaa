#include "evldt/lines/whole_lines.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <tuple>

namespace evldt {

namespace {

constexpr std::uint32_t kUnassigned = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t kNoKey = 0;
constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
constexpr float kLooseJoin = 2.0f;  // hysteresis: bounds for segments that were already one line
// Of b: a line taking back its former segments fits its own direction to them once they span this
// much (chosen on boxes-6dof and boxes-10s; 4 b did as well there and worse on flicker-lamps).
constexpr float kOwnFitRatio = 2.0f;
// Of b: a remembered end is kept only as far as the events along it go on, passing over runs
// without events up to this long (a block segment's worth). Chosen over 0.5 and 0.7 b on the
// built-in scenes (docs/whole-lines.md): an edge's events thin out towards its end, a gap between
// two objects is longer.
constexpr float kEndRunRatio = 1.0f;
// Where a published line's end reaches along the events beyond its segments (events_reach), in px.
// Chosen on the built-in scenes (docs/whole-lines.md): a radius of 1 px and runs of 2 px gained less
// recall; without the side test or the share, the reach ran on through night-boxes' noise; without
// the clearance, it ran on into the neighbouring lines of monitor-hd and tag-board.
constexpr float kReachEventRadius = 1.5f;  // a pixel is held by an event this close ...
constexpr float kReachSideOffset = 3.0f;   // ... unless events lie this far off the line on both sides too
constexpr float kReachMaxRun = 3.0f;       // the reach ends after a run this long without a held pixel
constexpr float kReachMinShare = 0.6f;     // it ends at a pixel only if this share of those passed are held
constexpr float kReachClearance = 3.0f;    // it stops short of coming this close to another published line
// A line is expected to move on at its velocity for at most this long since it last held segments
// (two output steps of 10 ms): further on, a wrong velocity costs more than a right one gains
// (100 ms lost three-lines-fast --motion-seed 41 IDF1 0.959 -> 0.903).
constexpr Timestamp kMaxPredictionUs = 20'000;

/// Where the ray from + u * direction (u >= 0) first comes within `radius` of segment s: the least u
/// in the capsule around s (its rectangle and the discs at its ends), or `none` if the ray misses it.
float first_approach(Point2 from, Point2 direction, const Segment& s, float radius, float none) {
  float first = none;
  for (const Point2& centre : {s.q0, s.q1}) {
    const Point2 w = centre - from;
    const float along = w.dot(direction), discriminant = along * along - (w.squaredNorm() - radius * radius);
    if (discriminant < 0) continue;
    const float root = std::sqrt(discriminant);
    if (along + root >= 0) first = std::min(first, std::max(0.0f, along - root));
  }
  const float length = s.length();
  if (!(length > 0)) return first;
  const Point2 e = (s.q1 - s.q0) / length, n(-e.y(), e.x());
  // The ray in the segment's frame, and the interval of u on it within the rectangle |t| <= radius,
  // 0 <= s <= length (slab by slab).
  float u_min = 0, u_max = std::numeric_limits<float>::infinity();
  const auto slab = [&](float start, float rate, float low, float high) {
    if (std::abs(rate) < 1e-9f) {
      if (start < low || start > high) u_max = -1;
      return;
    }
    const float a = (low - start) / rate, b = (high - start) / rate;
    u_min = std::max(u_min, std::min(a, b));
    u_max = std::min(u_max, std::max(a, b));
  };
  const Point2 w = from - s.q0;
  slab(w.dot(e), direction.dot(e), 0, length);
  slab(w.dot(n), direction.dot(n), -radius, radius);
  if (u_min <= u_max) first = std::min(first, u_min);
  return first;
}

}  // namespace

WholeLineTracker::WholeLineTracker(int block_size, const WholeLineParams& params, std::uint64_t first_id)
    : block_size_(static_cast<float>(block_size)),
      params_(params),
      cell_size_(static_cast<float>(block_size) * std::max(1.0f, params.max_gap_ratio + params.max_offset_ratio)),
      min_cos_angle_(std::cos(params_.max_angle_deg * std::numbers::pi_v<float> / 180.0f)),
      loose_cos_angle_(std::cos(std::min(90.0f, params_.loose_angle_deg) * std::numbers::pi_v<float> / 180.0f)),
      first_id_(first_id),
      next_id_(first_id) {
  if (first_id == 0) throw std::invalid_argument("whole-line ids start above 0");
  if (block_size <= 0)
    throw std::invalid_argument("whole lines need a positive block size, got " + std::to_string(block_size));
}

bool WholeLineTracker::fits(const LineModel& line, const Segment& segment, float relax, float gap_relax) const {
  const Point2 along = segment.q1 - segment.q0;
  const float length = along.norm();
  if (!(length > 0)) return false;
  const float min_cos = relax > 1.0f ? loose_cos_angle_ : min_cos_angle_;
  if (std::abs(along.dot(line.direction)) < min_cos * length) return false;
  const float max_offset = relax * params_.max_offset_ratio * block_size_;
  const Point2 a = segment.q0 - line.point, b = segment.q1 - line.point;
  if (std::abs(cross2(line.direction, a)) > max_offset || std::abs(cross2(line.direction, b)) > max_offset) {
    return false;
  }
  const float ta = a.dot(line.direction), tb = b.dot(line.direction);
  const float beyond_max = std::min(ta, tb) - line.t_max, before_min = line.t_min - std::max(ta, tb);
  const float gap = std::max({beyond_max, before_min, 0.0f});
  if (gap > gap_relax * params_.max_gap_ratio * block_size_) return false;
  // A segment that was this line's at the last step keeps its place without new evidence: the
  // gap was crossed on evidence when it joined, and a line does not split for a step's missing
  // events. A waiting line has no ends of now to bridge from: its gap bound is what holds it.
  if (gap == 0 || relax > 1.0f) return true;
  const Point2 end = line.point + (beyond_max > 0 ? line.t_max : line.t_min) * line.direction;
  return bridged(end, end + (beyond_max > 0 ? gap : -gap) * line.direction);
}

bool WholeLineTracker::bridged(Point2 from, Point2 to, float spread) const {
  const float length = (to - from).norm();
  if (events_ == nullptr || !(length > params_.max_unsupported_gap_ratio * block_size_)) return true;
  const int samples = static_cast<int>(std::ceil(length));
  // Half of the samples 0..samples, rounded up; the loop ends as soon as the answer is known.
  const int needed = (samples + 2) / 2;
  int supported = 0;
  for (int i = 0; i <= samples && supported < needed && supported + (samples + 1 - i) >= needed; ++i) {
    const float along = static_cast<float>(i) / static_cast<float>(samples);
    if (event_pixels_.any_within(from + (to - from) * along, 1.5f + spread * along * length)) ++supported;
  }
  return supported >= needed;
}

float WholeLineTracker::held_reach(Point2 from, Point2 to, float spread) const {
  const float length = (to - from).norm();
  if (events_ == nullptr) return length;
  const float max_run = kEndRunRatio * block_size_;
  const int samples = static_cast<int>(std::ceil(length));
  float last_held = 0;
  for (int i = 1; i <= samples; ++i) {
    const float distance = length * static_cast<float>(i) / static_cast<float>(samples);
    if (distance - last_held > max_run) break;
    // Once events are found, a rest no longer than a run is passed over.
    if (last_held > 0 && length - last_held <= max_run) return length;
    // A pixel nearer `from` than the tolerance may be held by the segments' own events at `from`.
    const float radius = 1.5f + spread * distance;
    if (distance > radius && event_pixels_.any_within(from + (to - from) * (distance / length), radius))
      last_held = distance;
  }
  return last_held;
}

std::uint64_t WholeLineTracker::former_track_of(std::uint64_t segment_id) const {
  const auto it = std::lower_bound(track_of_segment_id_.begin(), track_of_segment_id_.end(),
                                   std::pair(segment_id, std::uint64_t{0}));
  return it != track_of_segment_id_.end() && it->first == segment_id ? it->second : kNoKey;
}

void WholeLineTracker::add_member(Cluster& cluster, std::uint32_t s, std::span<const TrackedLine> segments) {
  cluster_of_segment_[s] = static_cast<std::uint32_t>(clusters_.size());
  members_.push_back(s);
  const Segment& segment = segments[s].segment;
  const double half = 0.5 * static_cast<double>(segment.length());
  for (const Point2& p : {segment.q0, segment.q1}) {
    const double x = p.x(), y = p.y();
    cluster.weight += half;
    cluster.sum_x += half * x;
    cluster.sum_y += half * y;
    cluster.sum_xx += half * x * x;
    cluster.sum_xy += half * x * y;
    cluster.sum_yy += half * y * y;
  }
  const double mx = cluster.sum_x / cluster.weight, my = cluster.sum_y / cluster.weight;
  const double cxx = cluster.sum_xx / cluster.weight - mx * mx;
  const double cxy = cluster.sum_xy / cluster.weight - mx * my;
  const double cyy = cluster.sum_yy / cluster.weight - my * my;
  // Principal axis of the ends; kept pointing the way the line pointed, so its ends keep their sides.
  const double angle = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
  Point2 direction(static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)));
  if (direction.dot(cluster.model.direction) < 0) direction = -direction;
  LineModel& model = cluster.model;
  model.direction = direction;
  model.point = Point2(static_cast<float>(mx), static_cast<float>(my));
  model.t_min = std::numeric_limits<float>::max();
  model.t_max = std::numeric_limits<float>::lowest();
  for (std::size_t m = cluster.first_member; m < members_.size(); ++m) {
    const Segment& member = segments[members_[m]].segment;
    for (const Point2& p : {member.q0, member.q1}) {
      const float t = (p - model.point).dot(direction);
      model.t_min = std::min(model.t_min, t);
      model.t_max = std::max(model.t_max, t);
    }
  }
}

void WholeLineTracker::grow(Cluster& cluster, std::uint64_t former_track, std::span<const TrackedLine> segments) {
  // Candidates are segments with an end in the 3 x 3 cells around an end of a member; a cell is as
  // wide as the gap and offset allowed, so no candidate is missed.
  for (std::size_t next = cluster.first_member; next < members_.size(); ++next) {
    const Segment& s = segments[members_[next]].segment;
    for (const Point2& end : {s.q0, s.q1}) {
      end_grid_.for_each_near(end, [&](std::uint32_t end_index) {
        const std::uint32_t k = end_index / 2;
        if (cluster_of_segment_[k] != kUnassigned) return;
        const bool was_member = former_track != kNoKey && former_track_of_segment_[k] == former_track;
        const float relax = was_member ? kLooseJoin : 1.0f;
        if (fits(cluster.model, segments[k].segment, relax, relax)) add_member(cluster, k, segments);
      });
    }
  }
}

std::size_t WholeLineTracker::first_fit_along(const LineModel& line, std::span<const TrackedLine> segments) const {
  const float length = line.t_max - line.t_min;
  const int samples = 1 + static_cast<int>(std::ceil(length / cell_size_));
  std::size_t found = kNone;
  for (int i = 0; i <= samples && found == kNone; ++i) {
    const Point2 at =
        line.point + (line.t_min + length * static_cast<float>(i) / static_cast<float>(samples)) * line.direction;
    end_grid_.for_each_near(at, [&](std::uint32_t end_index) {
      const std::uint32_t k = end_index / 2;
      if (found == kNone && cluster_of_segment_[k] == kUnassigned && fits(line, segments[k].segment, kLooseJoin, 1.0f))
        found = k;
    });
  }
  return found;
}

void WholeLineTracker::continue_track(Track& track, const Cluster& cluster, std::uint32_t members, Timestamp t) const {
  LineModel next = cluster.model;
  // Where the ends were, on the new line: an end the segments fall short of stays for end_memory_us.
  const Segment was = track.model.extent();
  const float was_min = (was.q0 - next.point).dot(next.direction);
  const float was_max = (was.q1 - next.point).dot(next.direction);
  // Only while the line itself is where it was: a line that turned or moved has no ends to keep.
  const bool same_line = fits({next.point, next.direction, was_min, was_max}, was, 1.0f, 1.0f);
  const float reach = 0.5f * block_size_;
  const auto at = [&](float along) -> Point2 { return next.point + along * next.direction; };
  // How far the end at `now` is kept out towards where it was, `before`.
  const auto kept = [&](Timestamp end_seen_us, float now, float before) {
    if (!same_line || !(std::abs(before - now) > reach) || t - end_seen_us > params_.end_memory_us) return 0.0f;
    const float held = held_reach(at(now), at(before), params_.extension_spread);
    return held > reach ? held : 0.0f;
  };
  const float kept_min = next.t_min > was_min ? kept(track.end_seen_us[0], next.t_min, was_min) : 0.0f;
  const float kept_max = next.t_max < was_max ? kept(track.end_seen_us[1], next.t_max, was_max) : 0.0f;
  if (kept_min > 0) {
    next.t_min -= kept_min;
  } else {
    track.end_seen_us[0] = t;
  }
  if (kept_max > 0) {
    next.t_max += kept_max;
  } else {
    track.end_seen_us[1] = t;
  }
  track.model = next;
  track.last_seen_us = t;
  track.segments = members;
}

WholeLineTracker::LineModel WholeLineTracker::expected_model(const Track& track, Timestamp t) const {
  LineModel model = track.model;
  const auto dt = static_cast<float>(std::min(t - track.last_seen_us, kMaxPredictionUs)) * 1e-6f;
  const Point2 normal(-model.direction.y(), model.direction.x());
  model.point += (track.velocity * dt) * normal;
  return model;
}

std::pair<float, float> WholeLineTracker::cluster_motion(std::size_t c, std::uint32_t members,
                                                         std::span<const TrackedLine> segments) const {
  const Point2 normal(-clusters_[c].model.direction.y(), clusters_[c].model.direction.x());
  double weights = 0, sum = 0, sum_squares = 0;
  const std::size_t first = clusters_[c].first_member;
  for (std::size_t m = first; m < first + members; ++m) {
    const TrackedLine& s = segments[members_[m]];
    const float sign = unit_normal(s.segment).dot(normal) < 0 ? -1.0f : 1.0f;
    const double velocity = sign * s.normal_velocity, deviation = std::max(s.normal_velocity_std, 1.0f);
    const double w = 1.0 / (deviation * deviation);
    weights += w;
    sum += w * velocity;
    sum_squares += w * velocity * velocity;
  }
  if (!(weights > 0)) return {0.0f, 0.0f};
  const double mean = sum / weights;
  const double spread = std::max(0.0, sum_squares / weights - mean * mean) / static_cast<double>(members);
  return {static_cast<float>(mean), static_cast<float>(std::sqrt(1.0 / weights + spread))};
}

bool WholeLineTracker::shadowed(const Segment& segment) const {
  return std::any_of(published_.begin(), published_.end(), [&](const WholeLine& line) {
    const Point2 along = line.segment.q1 - line.segment.q0;
    const float length = along.norm();
    if (!(length > 0)) return false;
    const Point2 direction = along / length;
    if (!fits({line.segment.q0, direction, 0.0f, length}, segment, kLooseJoin, kLooseJoin)) return false;
    // ... and covers at least half of it.
    const float ta = (segment.q0 - line.segment.q0).dot(direction), tb = (segment.q1 - line.segment.q0).dot(direction);
    const float covered = std::min(std::max(ta, tb), length) - std::max(std::min(ta, tb), 0.0f);
    return 2.0f * covered >= std::abs(tb - ta);
  });
}

float WholeLineTracker::events_reach(Point2 from, Point2 direction, float max_length) const {
  const Point2 normal(-direction.y(), direction.x());
  float reached = 0;
  int held = 0;
  for (int k = 1; k <= static_cast<int>(std::floor(max_length)); ++k) {
    const auto distance = static_cast<float>(k);
    if (distance - reached > kReachMaxRun) break;
    const Point2 at = from + distance * direction;
    if (!event_pixels_.any_within(at, kReachEventRadius)) continue;
    if (event_pixels_.any_within(at + kReachSideOffset * normal, kReachEventRadius) &&
        event_pixels_.any_within(at - kReachSideOffset * normal, kReachEventRadius)) {
      continue;
    }
    ++held;
    if (static_cast<float>(held) >= kReachMinShare * distance) reached = distance;
  }
  return reached;
}

void WholeLineTracker::reach_along_events() {
  const float max_reach = params_.event_reach_ratio * block_size_;
  if (events_ == nullptr || !(max_reach > 0) || published_.empty()) return;
  // Points every b/2 along each line, in cells of b: every line within the clearance of a point of a
  // stretch lies in the 3 x 3 cells around one of the stretch's points b/2 apart (for b >= 6).
  const float spacing = 0.5f * block_size_;
  line_samples_.clear();
  line_of_sample_.clear();
  for (std::uint32_t i = 0; i < published_.size(); ++i) {
    const Segment& s = published_[i].segment;
    const int steps = 1 + static_cast<int>(std::ceil(s.length() / spacing));
    for (int k = 0; k <= steps; ++k) {
      line_samples_.emplace_back(s.q0 + (s.q1 - s.q0) * (static_cast<float>(k) / static_cast<float>(steps)));
      line_of_sample_.push_back(i);
    }
  }
  line_grid_.build(block_size_, line_samples_);
  // Where the stretch from `from` first comes within the clearance of another line (or beyond max_reach).
  const auto clear_along = [&](std::uint32_t self, Point2 from, Point2 direction, float reach) {
    nearby_lines_.clear();
    const int queries = static_cast<int>(std::ceil(reach / spacing));
    for (int k = 0; k <= queries; ++k) {
      line_grid_.for_each_near(from + (static_cast<float>(k) * spacing) * direction, [&](std::uint32_t sample) {
        if (line_of_sample_[sample] != self) nearby_lines_.push_back(line_of_sample_[sample]);
      });
    }
    std::sort(nearby_lines_.begin(), nearby_lines_.end());
    nearby_lines_.erase(std::unique(nearby_lines_.begin(), nearby_lines_.end()), nearby_lines_.end());
    float clear = max_reach + 1;
    for (const std::uint32_t other : nearby_lines_) {
      clear = std::min(clear, first_approach(from, direction, published_[other].segment, kReachClearance, clear));
    }
    return clear;
  };
  reached_.clear();
  for (std::uint32_t i = 0; i < published_.size(); ++i) {
    Segment s = published_[i].segment;
    const float length = s.length();
    if (!(length > 0)) {
      reached_.push_back(s);
      continue;
    }
    const Point2 along = (s.q1 - s.q0) / length;
    for (Point2* end : {&s.q1, &s.q0}) {
      const Point2 from = *end, direction = end == &s.q1 ? along : Point2(-along);
      float reach = events_reach(from, direction, max_reach);
      // Only pixels short of where the stretch comes near another line: the walk to them alone ends
      // where this one did if that is short of it (asked only of the ends that reach out at all).
      if (reach > 0) {
        const float clear = clear_along(i, from, direction, reach);
        if (clear <= reach) reach = events_reach(from, direction, std::ceil(clear) - 1);
      }
      *end = from + reach * direction;
    }
    reached_.push_back(s);
  }
  for (std::uint32_t i = 0; i < published_.size(); ++i) published_[i].segment = reached_[i];
}

void WholeLineTracker::meet_at_corners() {
  const float reach = params_.corner_reach_ratio * block_size_;
  if (!(reach > 0) || published_.size() < 2) return;
  const float min_sin = std::sin(params_.corner_min_angle_deg * std::numbers::pi_v<float> / 180.0f);
  const auto end_point = [&](std::uint32_t end) -> Point2& {
    Segment& s = published_[end / 2].segment;
    return end % 2 == 0 ? s.q0 : s.q1;
  };
  // An end that would grow to the corner does so only where the events reach it (a crossing of two
  // edges that only nearly meet is no corner); one past the corner is always drawn back to it. Of
  // the lines as they were before any end moved (ends_).
  const auto reaches = [&](std::uint32_t end, Point2 at) {
    const Point2 from = ends_[end], other = ends_[end ^ 1];
    return (at - from).dot(from - other) <= 0 || bridged(from, at, params_.extension_spread);
  };
  ends_.clear();
  for (std::uint32_t end = 0; end < 2 * published_.size(); ++end) ends_.push_back(end_point(end));
  // Two ends within reach of one corner are within 2 reach of each other: cells that wide, 3 x 3 of them.
  corner_grid_.build(2.0f * reach, ends_);
  corners_.clear();
  for (std::uint32_t a = 0; a < 2 * published_.size(); ++a) {
    const Segment& line_a = published_[a / 2].segment;
    const Point2 pa = end_point(a), da = (line_a.q1 - line_a.q0).normalized();
    corner_grid_.for_each_near(pa, [&](std::uint32_t b) {
      if (b / 2 <= a / 2) return;  // each pair of lines once, never a line with itself
      const Segment& line_b = published_[b / 2].segment;
      const Point2 pb = end_point(b), db = (line_b.q1 - line_b.q0).normalized();
      const float sine = cross2(da, db);
      if (!(std::abs(sine) >= std::max(min_sin, 1e-6f))) return;  // also a zero-length line's NaN, and parallel lines
      const Point2 at = pa + (cross2(pb - pa, db) / sine) * da;
      if ((at - pa).norm() > reach || (at - pb).norm() > reach) return;
      corners_.push_back({(at - pa).norm() + (at - pb).norm(), a, b, at});
    });
  }
  // Nearest corners first; an end meets one corner. The events are asked only of the corners that
  // would be made (the lattice check is the costly part): one they refuse leaves both ends free.
  std::sort(corners_.begin(), corners_.end(), [](const Corner& x, const Corner& y) {
    return x.cost != y.cost ? x.cost < y.cost : std::pair(x.end_a, x.end_b) < std::pair(y.end_a, y.end_b);
  });
  end_moved_.assign(2 * published_.size(), 0);
  for (const Corner& corner : corners_) {
    if (end_moved_[corner.end_a] != 0 || end_moved_[corner.end_b] != 0) continue;
    if (!reaches(corner.end_a, corner.at) || !reaches(corner.end_b, corner.at)) continue;
    end_moved_[corner.end_a] = end_moved_[corner.end_b] = 1;
    end_point(corner.end_a) = corner.at;
    end_point(corner.end_b) = corner.at;
  }
}

void WholeLineTracker::update(Timestamp t, std::span<const TrackedLine> segments, const ScarfLattice* events) {
  if (stepped_ && t < last_t_) throw std::invalid_argument("whole-line steps must come in time order");
  events_ = events;
  event_pixels_.reset(events);
  stepped_ = true;
  last_t_ = t;
  // Association: which segments make each line, and which line keeps which id.
  index_segments(segments);
  const std::size_t first_new_cluster = associate(t, segments);
  carry_tracks_over(t, first_new_cluster, segments);
  publish(t);
  // End geometry: the published lines' ends drawn out along the events and met at corners.
  reach_along_events();
  meet_at_corners();
  events_ = nullptr;  // the caller's lattice is not kept past the step
  event_pixels_.reset(nullptr);
}

void WholeLineTracker::index_segments(std::span<const TrackedLine> segments) {
  const auto n = static_cast<std::uint32_t>(segments.size());
  ends_.clear();
  segments_of_former_track_.clear();
  former_track_of_segment_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    ends_.push_back(segments[i].segment.q0);
    ends_.push_back(segments[i].segment.q1);
    const std::uint64_t former = former_track_of(segments[i].id);
    former_track_of_segment_[i] = former;
    if (former != kNoKey) segments_of_former_track_.emplace_back(former, i);
  }
  end_grid_.build(cell_size_, ends_);
  // Longest segments first, of a line's former segments and of new lines' seeds, so a line's direction
  // comes from its best evidence.
  const auto longer = [&](std::uint32_t a, std::uint32_t b) {
    const float la = segments[a].segment.length(), lb = segments[b].segment.length();
    return la != lb ? la > lb : segments[a].id < segments[b].id;
  };
  std::sort(segments_of_former_track_.begin(), segments_of_former_track_.end(), [&](const auto& a, const auto& b) {
    return a.first != b.first ? a.first < b.first : longer(a.second, b.second);
  });
  order_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) order_[i] = i;
  std::sort(order_.begin(), order_.end(), longer);
}

std::size_t WholeLineTracker::associate(Timestamp t, std::span<const TrackedLine> segments) {
  cluster_of_segment_.assign(segments.size(), kUnassigned);
  clusters_.clear();
  cluster_of_track_.assign(tracks_.size(), kNone);
  members_.clear();
  // Published lines that take back segments go before those that wait: a waiting line looks for
  // its edge among the segments no published line took, so its old geometry does not take up
  // another published line's edge (and id with it). Lines not yet published come last.
  const auto published_count = static_cast<std::size_t>(
      std::find_if(tracks_.begin(), tracks_.end(), [](const Track& track) { return track.id == 0; }) - tracks_.begin());
  for (std::size_t k = 0; k < published_count; ++k) follow_track(k, t, true, false, segments);
  for (std::size_t k = 0; k < published_count; ++k) follow_track(k, t, false, true, segments);
  for (std::size_t k = published_count; k < tracks_.size(); ++k) follow_track(k, t, true, true, segments);
  // New lines from the segments left.
  const std::size_t first_new_cluster = clusters_.size();
  for (const std::uint32_t seed : order_) {
    if (cluster_of_segment_[seed] != kUnassigned || !(segments[seed].segment.length() > 0)) continue;
    const Segment& s = segments[seed].segment;
    Cluster cluster;
    cluster.first_member = members_.size();
    cluster.model.direction = (s.q1 - s.q0).normalized();
    add_member(cluster, seed, segments);
    grow(cluster, former_track_of_segment_[seed], segments);
    clusters_.push_back(cluster);
  }
  return first_new_cluster;
}

void WholeLineTracker::follow_track(std::size_t k, Timestamp t, bool take_back, bool look_along,
                                    std::span<const TrackedLine> segments) {
  const Track& track = tracks_[k];
  if (t - track.last_seen_us > params_.keep_id_us || cluster_of_track_[k] != kNone) return;
  const LineModel expected = expected_model(track, t);
  Cluster cluster;
  cluster.model = expected;
  cluster.first_member = members_.size();
  auto it = std::lower_bound(segments_of_former_track_.begin(), segments_of_former_track_.end(),
                             std::pair(track.key, std::uint32_t{0}),
                             [](const auto& a, const auto& b) { return a.first < b.first; });
  for (; take_back && it != segments_of_former_track_.end() && it->first == track.key; ++it) {
    // Its former segments are taken back along its last geometry until those taken back span
    // enough to fit a direction of their own: one tilted segment taken back first (the longest,
    // at a corner) would else steer the line off its edge and leave the rest, and with it the
    // edge's id, to a younger line.
    const bool own_fit = members_.size() > cluster.first_member &&
                         cluster.model.t_max - cluster.model.t_min >= kOwnFitRatio * block_size_;
    if (cluster_of_segment_[it->second] == kUnassigned &&
        fits(own_fit ? cluster.model : expected, segments[it->second].segment, kLooseJoin, kLooseJoin)) {
      add_member(cluster, it->second, segments);
    }
  }
  if (members_.size() == cluster.first_member) {
    const std::size_t found = look_along ? first_fit_along(expected, segments) : kNone;
    if (found == kNone) return;  // waits, under its last geometry
    add_member(cluster, static_cast<std::uint32_t>(found), segments);
  }
  grow(cluster, track.key, segments);
  cluster_of_track_[k] = clusters_.size();
  clusters_.push_back(cluster);
}

std::uint32_t WholeLineTracker::members_of(std::size_t c) const {
  const std::size_t end = c + 1 < clusters_.size() ? clusters_[c + 1].first_member : members_.size();
  return static_cast<std::uint32_t>(end - clusters_[c].first_member);
}

void WholeLineTracker::carry_tracks_over(Timestamp t, std::size_t first_new_cluster,
                                         std::span<const TrackedLine> segments) {
  next_tracks_.clear();
  next_track_of_segment_id_.clear();
  const auto take_ownership = [&](std::size_t c, std::uint64_t key) {
    const std::size_t first = clusters_[c].first_member;
    for (std::size_t m = first; m < first + members_of(c); ++m)
      next_track_of_segment_id_.emplace_back(segments[members_[m]].id, key);
  };
  for (std::size_t k = 0; k < tracks_.size(); ++k) {
    Track& track = tracks_[k];
    if (const std::size_t c = cluster_of_track_[k]; c != kNone) {
      continue_track(track, clusters_[c], members_of(c), t);
      std::tie(track.velocity, track.velocity_std) = cluster_motion(c, members_of(c), segments);
      take_ownership(c, track.key);
    } else if (track.id == 0 || t - track.last_seen_us > params_.keep_id_us) {
      continue;  // ended (a line never published has no id to keep)
    } else {
      track.segments = 0;  // waiting
    }
    next_tracks_.push_back(track);
  }
  for (std::size_t c = first_new_cluster; c < clusters_.size(); ++c) {
    Track track{.key = next_key_++,
                .model = clusters_[c].model,
                .first_seen_us = t,
                .last_seen_us = t,
                .end_seen_us = {t, t},
                .segments = members_of(c)};
    std::tie(track.velocity, track.velocity_std) = cluster_motion(c, members_of(c), segments);
    take_ownership(c, track.key);
    next_tracks_.push_back(track);
  }
  tracks_.swap(next_tracks_);
  std::sort(next_track_of_segment_id_.begin(), next_track_of_segment_id_.end());
  track_of_segment_id_.swap(next_track_of_segment_id_);
}

void WholeLineTracker::publish(Timestamp t) {
  published_.clear();
  const float min_length = params_.min_length_ratio * block_size_;
  for (Track& track : tracks_) {
    if (track.segments == 0) continue;
    if (track.id == 0 && track.model.t_max - track.model.t_min < min_length) continue;
    const Segment segment = track.model.extent();
    if (track.id == 0 && shadowed(segment)) continue;
    if (track.id == 0) track.id = next_id_++;
    published_.push_back({.id = track.id,
                          .segment = segment,
                          .segments = track.segments,
                          .first_seen_us = track.first_seen_us,
                          .last_seen_us = t,
                          .normal_velocity = track.velocity,
                          .normal_velocity_std = track.velocity_std});
  }
  // Published lines first, in the order they were published, then the rest by age: in a merge the
  // line published first keeps its id.
  std::sort(tracks_.begin(), tracks_.end(), [](const Track& a, const Track& b) {
    return std::tuple(a.id == 0, a.id, a.key) < std::tuple(b.id == 0, b.id, b.key);
  });
}

}  // namespace evldt
