#include "evldt/lines/whole_lines.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace evldt {

namespace {

constexpr std::uint32_t kUnassigned = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t kNoId = 0;
constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

}  // namespace

WholeLineTracker::WholeLineTracker(int block_size, const WholeLineParams& params, std::uint64_t first_id)
    : block_size_(static_cast<float>(block_size)),
      params_(params),
      cell_size_(static_cast<float>(block_size) * std::max(1.0f, params.max_gap_ratio + params.max_offset_ratio)),
      min_cos_angle_(std::cos(params_.max_angle_deg * std::numbers::pi_v<float> / 180.0f)),
      loose_cos_angle_(std::cos(std::min(90.0f, 2.0f * params_.max_angle_deg) * std::numbers::pi_v<float> / 180.0f)),
      first_id_(first_id),
      next_id_(first_id) {
  if (first_id == kNoId) throw std::invalid_argument("whole-line ids start above 0");
  if (block_size <= 0) throw std::invalid_argument("whole lines need a positive block size, got " + std::to_string(block_size));
}

std::int64_t WholeLineTracker::cell_of(const Point2& p) const {
  const auto cx = static_cast<std::int64_t>(std::floor(p.x() / cell_size_));
  const auto cy = static_cast<std::int64_t>(std::floor(p.y() / cell_size_));
  return (cy << 32) + cx;
}

bool WholeLineTracker::fits(const Cluster& cluster, const Segment& segment, bool together_before) const {
  const Point2 along = segment.q1 - segment.q0;
  const float length = along.norm();
  if (!(length > 0)) return false;
  const float relax = together_before ? 2.0f : 1.0f;
  if (std::abs(along.dot(cluster.direction)) < (together_before ? loose_cos_angle_ : min_cos_angle_) * length) return false;
  const float max_offset = relax * params_.max_offset_ratio * block_size_;
  const Point2 a = segment.q0 - cluster.point, b = segment.q1 - cluster.point;
  if (std::abs(cross2(cluster.direction, a)) > max_offset || std::abs(cross2(cluster.direction, b)) > max_offset) {
    return false;
  }
  const float ta = a.dot(cluster.direction), tb = b.dot(cluster.direction);
  const float gap = std::max({std::min(ta, tb) - cluster.t_max, cluster.t_min - std::max(ta, tb), 0.0f});
  return gap <= relax * params_.max_gap_ratio * block_size_;
}

void WholeLineTracker::add_member(Cluster& cluster, std::size_t first, std::span<const TrackedLine> segments) const {
  const Segment& s = segments[members_.back()].segment;
  const double half = 0.5 * static_cast<double>(s.length());
  for (const Point2& p : {s.q0, s.q1}) {
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
  // Principal axis of the ends; kept pointing the way it pointed, so extents keep their sign.
  const double angle = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
  Point2 direction(static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)));
  if (first + 1 == members_.size()) {
    const Point2 along = s.q1 - s.q0;
    if (direction.dot(along) < 0) direction = -direction;
  } else if (direction.dot(cluster.direction) < 0) {
    direction = -direction;
  }
  cluster.direction = direction;
  cluster.point = Point2(static_cast<float>(mx), static_cast<float>(my));
  cluster.t_min = std::numeric_limits<float>::max();
  cluster.t_max = std::numeric_limits<float>::lowest();
  for (std::size_t m = first; m < members_.size(); ++m) {
    const Segment& member = segments[members_[m]].segment;
    for (const Point2& p : {member.q0, member.q1}) {
      const float t = (p - cluster.point).dot(direction);
      cluster.t_min = std::min(cluster.t_min, t);
      cluster.t_max = std::max(cluster.t_max, t);
    }
  }
}

std::uint64_t WholeLineTracker::previous_owner(std::uint64_t segment_id) const {
  const auto it = std::lower_bound(owner_.begin(), owner_.end(), std::pair(segment_id, std::uint64_t{0}));
  return it != owner_.end() && it->first == segment_id ? it->second : kNoId;
}

std::size_t WholeLineTracker::find_ended(const Cluster& cluster, Timestamp t) const {
  const float max_offset = 0.5f * block_size_;
  std::size_t best = kNone;
  float best_offset = 0;
  for (std::size_t e = 0; e < ended_.size(); ++e) {
    const WholeLine& earlier = ended_[e];
    if (earlier.id == kNoId || t - earlier.last_seen_us > params_.keep_id_us) continue;
    const Point2 along = earlier.segment.q1 - earlier.segment.q0;
    const float length = along.norm();
    if (!(length > 0) || std::abs(along.dot(cluster.direction)) < min_cos_angle_ * length) continue;
    const Point2 centre = earlier.segment.centre() - cluster.point;
    const float offset = std::abs(cross2(cluster.direction, centre));
    const float ta = (earlier.segment.q0 - cluster.point).dot(cluster.direction);
    const float tb = (earlier.segment.q1 - cluster.point).dot(cluster.direction);
    const bool overlaps = std::max(ta, tb) >= cluster.t_min && std::min(ta, tb) <= cluster.t_max;
    if (offset > max_offset || !overlaps || (best != kNone && offset >= best_offset)) continue;
    best = e;
    best_offset = offset;
  }
  return best;
}

void WholeLineTracker::update(Timestamp t, std::span<const TrackedLine> segments) {
  if (stepped_ && t < last_t_) throw std::invalid_argument("whole-line steps must come in time order");
  stepped_ = true;
  last_t_ = t;
  const auto n = static_cast<std::uint32_t>(segments.size());

  grid_.clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    grid_.emplace_back(cell_of(segments[i].segment.q0), i);
    grid_.emplace_back(cell_of(segments[i].segment.q1), i);
  }
  std::sort(grid_.begin(), grid_.end());
  // Longest segments seed lines first, so a line's direction comes from its best evidence.
  order_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) order_[i] = i;
  std::sort(order_.begin(), order_.end(), [&](std::uint32_t a, std::uint32_t b) {
    const float la = segments[a].segment.length(), lb = segments[b].segment.length();
    return la != lb ? la > lb : segments[a].id < segments[b].id;
  });

  cluster_of_segment_.assign(n, kUnassigned);
  clusters_.clear();
  cluster_start_.clear();
  members_.clear();
  for (const std::uint32_t seed : order_) {
    if (cluster_of_segment_[seed] != kUnassigned || !(segments[seed].segment.length() > 0)) continue;
    const auto c = static_cast<std::uint32_t>(clusters_.size());
    const std::size_t first = members_.size();
    cluster_start_.push_back(first);
    Cluster cluster;
    const std::uint64_t seed_owner = previous_owner(segments[seed].id);
    cluster_of_segment_[seed] = c;
    members_.push_back(seed);
    add_member(cluster, first, segments);
    // Grow along the edge: candidates are segments with an end in the 3 x 3 cells around an end of a
    // member; a cell is as wide as the gap and offset allowed, so no candidate is missed.
    for (std::size_t next = first; next < members_.size(); ++next) {
      const Segment& s = segments[members_[next]].segment;
      for (const Point2& end : {s.q0, s.q1}) {
        const std::int64_t centre = cell_of(end);
        for (std::int64_t dy = -1; dy <= 1; ++dy) {
          for (std::int64_t dx = -1; dx <= 1; ++dx) {
            const std::int64_t cell = centre + (dy << 32) + dx;
            auto it = std::lower_bound(grid_.begin(), grid_.end(), std::pair(cell, std::uint32_t{0}));
            for (; it != grid_.end() && it->first == cell; ++it) {
              const std::uint32_t k = it->second;
              if (cluster_of_segment_[k] != kUnassigned) continue;
              const std::uint64_t owner = previous_owner(segments[k].id);
              if (!fits(cluster, segments[k].segment, owner != kNoId && owner == seed_owner)) continue;
              cluster_of_segment_[k] = c;
              members_.push_back(k);
              add_member(cluster, first, segments);
            }
          }
        }
      }
    }
    clusters_.push_back(cluster);
  }
  cluster_start_.push_back(members_.size());
  const std::size_t count = clusters_.size();

  // Ids: each earlier line goes to the new line holding most of its segments' length.
  votes_.clear();
  for (std::size_t c = 0; c < count; ++c) {
    for (std::size_t m = cluster_start_[c]; m < cluster_start_[c + 1]; ++m) {
      const TrackedLine& s = segments[members_[m]];
      const std::uint64_t owner = previous_owner(s.id);
      if (owner != kNoId) votes_.push_back({c, owner, s.segment.length()});
    }
  }
  std::sort(votes_.begin(), votes_.end(), [](const Vote& a, const Vote& b) {
    return a.cluster != b.cluster ? a.cluster < b.cluster : a.id < b.id;
  });
  std::size_t merged = 0;
  for (std::size_t v = 0; v < votes_.size(); ++v) {
    if (merged > 0 && votes_[merged - 1].cluster == votes_[v].cluster && votes_[merged - 1].id == votes_[v].id) {
      votes_[merged - 1].length += votes_[v].length;
    } else {
      votes_[merged++] = votes_[v];
    }
  }
  votes_.resize(merged);
  std::sort(votes_.begin(), votes_.end(), [](const Vote& a, const Vote& b) {
    if (a.length != b.length) return a.length > b.length;
    return a.id != b.id ? a.id < b.id : a.cluster < b.cluster;
  });
  id_of_cluster_.assign(count, kNoId);
  first_seen_of_cluster_.assign(count, t);
  line_of_id_.clear();
  for (std::size_t i = 0; i < lines_.size(); ++i) line_of_id_.emplace_back(lines_[i].id, i);
  std::sort(line_of_id_.begin(), line_of_id_.end());
  for (const Vote& v : votes_) {
    if (id_of_cluster_[v.cluster] != kNoId) continue;
    const auto it = std::lower_bound(line_of_id_.begin(), line_of_id_.end(), std::pair(v.id, std::size_t{0}));
    WholeLine& previous = lines_[it->second];  // every voted id is one of the last step's lines
    if (previous.last_seen_us < 0) continue;  // taken by a line holding more of it
    id_of_cluster_[v.cluster] = v.id;
    first_seen_of_cluster_[v.cluster] = previous.first_seen_us;
    previous.last_seen_us = -1;  // marks it taken
  }
  // Earlier lines nobody took have ended; they may be taken up again within keep_id_us.
  for (const WholeLine& l : lines_) {
    if (l.last_seen_us >= 0) ended_.push_back(l);
  }
  std::erase_if(ended_, [&](const WholeLine& l) { return l.id == kNoId || t - l.last_seen_us > params_.keep_id_us; });
  for (std::size_t c = 0; c < count; ++c) {
    if (id_of_cluster_[c] != kNoId) continue;
    const std::size_t e = find_ended(clusters_[c], t);
    if (e != kNone) {
      id_of_cluster_[c] = ended_[e].id;
      first_seen_of_cluster_[c] = ended_[e].first_seen_us;
      ended_[e].id = kNoId;  // taken
    } else {
      id_of_cluster_[c] = next_id_++;
    }
  }

  lines_.clear();
  next_owner_.clear();
  for (std::size_t c = 0; c < count; ++c) {
    const Cluster& cluster = clusters_[c];
    WholeLine line;
    line.id = id_of_cluster_[c];
    line.segment = {cluster.point + cluster.t_min * cluster.direction, cluster.point + cluster.t_max * cluster.direction};
    line.segments = static_cast<std::uint32_t>(cluster_start_[c + 1] - cluster_start_[c]);
    line.first_seen_us = first_seen_of_cluster_[c];
    line.last_seen_us = t;
    lines_.push_back(line);
    for (std::size_t m = cluster_start_[c]; m < cluster_start_[c + 1]; ++m) {
      next_owner_.emplace_back(segments[members_[m]].id, line.id);
    }
  }
  std::sort(next_owner_.begin(), next_owner_.end());
  owner_.swap(next_owner_);
}

void as_tracked_lines(std::span<const WholeLine> lines, std::vector<TrackedLine>& out) {
  out.clear();
  for (const WholeLine& l : lines) {
    out.push_back({.id = l.id,
                   .segment = l.segment,
                   .score = static_cast<float>(l.segments),
                   .status = LineStatus::GoodTrack,
                   .admin_block = -1,
                   .first_seen_us = l.first_seen_us,
                   .last_good_us = l.last_seen_us});
  }
}

}  // namespace evldt
