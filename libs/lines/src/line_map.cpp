#include "evldt/lines/line_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace evldt {

std::string_view reason_name(ReleaseReason reason) {
  switch (reason) {
    case ReleaseReason::TooFewPoints:
      return "too-few-points";
    case ReleaseReason::TooShort:
      return "too-short";
    case ReleaseReason::LeftSensor:
      return "left-sensor";
    case ReleaseReason::BadTracks:
      return "bad-tracks";
    case ReleaseReason::LostOwnership:
      return "lost-ownership";
  }
  return "?";
}

LineMap::LineMap(const LatticeGeometry& geometry, const ReassociationParams& reassociation, const MotionParams& motion)
    : geometry_(geometry),
      reassociation_(reassociation),
      motion_params_(motion),
      min_cos_angle_(std::cos(reassociation.max_angle_deg * std::numbers::pi_v<float> / 180.0f)),
      released_by_block_(static_cast<std::size_t>(geometry.block_count())),
      status_(static_cast<std::size_t>(geometry.block_count()), BlockStatus::NoDetect),
      owner_(static_cast<std::size_t>(geometry.block_count()), -1) {
  lines_.reserve(static_cast<std::size_t>(geometry.block_count()));  // at most one line per block
  settled_.reserve(lines_.capacity());
  motion_.reserve(lines_.capacity());
  band_centre_.reserve(lines_.capacity());
}

void LineMap::set_block_status(int block, BlockStatus status) {
  if (status == BlockStatus::Owned || status_[block] == BlockStatus::Owned) {
    throw std::logic_error("block ownership changes only through add/release/manage");
  }
  status_[block] = status;
}

std::uint64_t LineMap::add(const Segment& segment, float score, int admin_block, Timestamp now) {
  if (status_[admin_block] == BlockStatus::Owned) throw std::logic_error("a block administers at most one line");
  TrackedLine line;
  line.segment = segment;
  line.score = score;
  line.admin_block = admin_block;
  line.first_seen_us = now;
  line.last_good_us = now;
  NormalMotion motion;
  start_motion(motion, segment, now, motion_params_);
  // The edge's motion goes on: the new segment is where the edge is now, moving as it did.
  const auto take_velocity = [&](const NormalMotion& edge) {
    motion.velocity = unit_normal(segment).dot(edge.normal) < 0 ? -edge.velocity : edge.velocity;
    motion.var_velocity = edge.var_velocity;
  };
  if (ReleasedLine* earlier = find_released(segment, admin_block, now)) {
    line.id = earlier->id;
    line.first_seen_us = earlier->first_seen_us;
    released_lifetimes_.take_back(earlier->last_good_us - earlier->first_seen_us);
    earlier->present = false;
    ++reassociated_;
    take_velocity(earlier->motion);
  } else {
    line.id = next_id_++;
    if (const NormalMotion* along = neighbour_motion(segment, admin_block)) take_velocity(*along);
  }
  line.normal_velocity = motion.velocity;
  line.normal_velocity_std = motion.velocity_std();
  status_[admin_block] = BlockStatus::Owned;
  owner_[admin_block] = static_cast<std::int32_t>(lines_.size());
  lines_.push_back(line);
  settled_.push_back(0);
  motion_.push_back(motion);
  band_centre_.push_back(segment.centre());
  return line.id;
}

float LineMap::offset_along(const Segment& line, Point2 direction, Point2 centre) const {
  const Point2 along = line.q1 - line.q0;
  const float length = along.norm();
  if (!(length > 0) || std::abs(direction.dot(along)) < min_cos_angle_ * length)
    return std::numeric_limits<float>::infinity();
  return std::abs(cross2(along, centre - line.q0)) / length;
}

LineMap::ReleasedLine* LineMap::find_released(const Segment& segment, int block, Timestamp now) {
  if (reassociation_.window_us <= 0) return nullptr;
  const float length = segment.length();
  if (!(length > 0)) return nullptr;
  const Point2 direction = (segment.q1 - segment.q0) / length;
  const Point2 centre = segment.centre();
  const float max_offset = reassociation_.max_offset_ratio * static_cast<float>(geometry_.block_size);
  ReleasedLine* best = nullptr;
  float best_offset = 0;
  const int i = geometry_.column(block), j = geometry_.row(block);
  for (int nj = std::max(0, j - 1); nj <= std::min(geometry_.blocks_y - 1, j + 1); ++nj) {
    for (int ni = std::max(0, i - 1); ni <= std::min(geometry_.blocks_x - 1, i + 1); ++ni) {
      ReleasedLine& candidate = released_by_block_[static_cast<std::size_t>(geometry_.index(ni, nj))];
      if (!candidate.present || now - candidate.last_good_us > reassociation_.window_us) continue;
      const float offset = offset_along(candidate.segment, direction, centre);
      if (offset > max_offset || (best != nullptr && offset >= best_offset)) continue;
      best = &candidate;
      best_offset = offset;
    }
  }
  return best;
}

const NormalMotion* LineMap::neighbour_motion(const Segment& segment, int block) const {
  const float max_offset = reassociation_.max_offset_ratio * static_cast<float>(geometry_.block_size);
  const Point2 direction = (segment.q1 - segment.q0).normalized(), centre = segment.centre();
  const NormalMotion* best = nullptr;
  float best_offset = 0;
  const int i = geometry_.column(block), j = geometry_.row(block);
  for (int nj = std::max(0, j - 1); nj <= std::min(geometry_.blocks_y - 1, j + 1); ++nj) {
    for (int ni = std::max(0, i - 1); ni <= std::min(geometry_.blocks_x - 1, i + 1); ++ni) {
      const int owner = owner_[static_cast<std::size_t>(geometry_.index(ni, nj))];
      if (owner < 0) continue;
      const auto index = static_cast<std::size_t>(owner);
      const float offset = offset_along(lines_[index].segment, direction, centre);
      if (offset > max_offset || (best != nullptr && offset >= best_offset)) continue;
      best = &motion_[index];
      best_offset = offset;
    }
  }
  return best;
}

void LineMap::release(std::size_t index, ReleaseReason reason) {
  const int block = lines_[index].admin_block;
  const TrackedLine& gone = lines_[index];
  released_lifetimes_.add(gone.last_good_us - gone.first_seen_us);
  released_by_block_[static_cast<std::size_t>(block)] = {
      true, gone.id, gone.segment, gone.first_seen_us, gone.last_good_us, motion_[index]};
  status_[block] = BlockStatus::NoDetect;
  owner_[block] = -1;
  if (index + 1 != lines_.size()) {
    lines_[index] = lines_.back();
    settled_[index] = settled_.back();
    motion_[index] = motion_.back();
    band_centre_[index] = band_centre_.back();
    owner_[lines_[index].admin_block] = static_cast<std::int32_t>(index);
  }
  lines_.pop_back();
  settled_.pop_back();
  motion_.pop_back();
  band_centre_.pop_back();
  ++released_[static_cast<int>(reason)];
}

void LineMap::manage(float suppress_ratio) {
  transfer_ownership();
  suppress_detection(suppress_ratio);
}

void LineMap::transfer_ownership() {
  std::size_t i = 0;
  while (i < lines_.size()) {
    TrackedLine& line = lines_[i];
    const Point2 centre = line.segment.centre();
    const int target = geometry_.block_at(centre.x(), centre.y());
    if (target < 0 || target == line.admin_block) {  // off the lattice's active area: keep the admin
      ++i;
      continue;
    }
    if (status_[target] == BlockStatus::Owned) {
      const auto resident = static_cast<std::size_t>(owner_[target]);
      if (lines_[resident].score >= line.score) {  // ties keep the resident: no churn
        release(i, ReleaseReason::LostOwnership);  // a swapped-in line now sits at i: revisit it
        continue;
      }
      // Swap-remove: if the mover was last it now sits in the resident's slot. If the resident sat
      // before i, the line swapped into its slot waits for the next round's transfer.
      release(resident, ReleaseReason::LostOwnership);
      if (i == lines_.size()) i = resident;
    }
    TrackedLine& mover = lines_[i];
    status_[mover.admin_block] = BlockStatus::NoDetect;
    owner_[mover.admin_block] = -1;
    mover.admin_block = target;
    status_[target] = BlockStatus::Owned;
    owner_[target] = static_cast<std::int32_t>(i);
    ++i;
  }
}

void LineMap::suppress_detection(float suppress_ratio) {
  const float reach = suppress_ratio * static_cast<float>(geometry_.block_size);
  const float b = static_cast<float>(geometry_.block_size);
  for (const TrackedLine& line : lines_) {
    const int i = geometry_.column(line.admin_block);
    const int j = geometry_.row(line.admin_block);
    const Point2 c = line.segment.centre();
    const float x0 = geometry_.origin_x(i), y0 = geometry_.origin_y(j);
    auto prohibit = [&](int ni, int nj) {
      if (ni < 0 || nj < 0 || ni >= geometry_.blocks_x || nj >= geometry_.blocks_y) return;
      const int block = geometry_.index(ni, nj);
      if (status_[block] == BlockStatus::NoDetect) status_[block] = BlockStatus::ProhibitDetection;
    };
    if (c.x() - x0 < reach) prohibit(i - 1, j);
    if (x0 + b - c.x() < reach) prohibit(i + 1, j);
    if (c.y() - y0 < reach) prohibit(i, j - 1);
    if (y0 + b - c.y() < reach) prohibit(i, j + 1);
  }
}

void LineMap::set_first_id(std::uint64_t first) {
  if (!lines_.empty()) throw std::logic_error("set_first_id before any line exists");
  first_id_ = next_id_ = first;
}

void LineMap::clear() {
  std::fill(status_.begin(), status_.end(), BlockStatus::NoDetect);
  std::fill(owner_.begin(), owner_.end(), -1);
  std::fill(released_by_block_.begin(), released_by_block_.end(), ReleasedLine{});
  lines_.clear();
  settled_.clear();
  motion_.clear();
  band_centre_.clear();
}

void LineMap::observe_motion(Timestamp now) {
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    TrackedLine& line = lines_[i];
    if (line.status != LineStatus::GoodTrack) continue;
    evldt::observe_motion(motion_[i], line.segment, band_centre_[i], now, motion_params_);
    line.normal_velocity = motion_[i].velocity;
    line.normal_velocity_std = motion_[i].velocity_std();
  }
}

}  // namespace evldt
