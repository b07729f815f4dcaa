#include "evldt/lines/detector.hpp"

#include <cmath>

#include "evldt/lines/line_fit.hpp"

namespace evldt {

namespace {
constexpr std::uint64_t kNeverFailed = UINT64_MAX;
}  // namespace

LineDetector::LineDetector(const LatticeGeometry& geometry, const ScoreParams& params)
    : geometry_(geometry),
      params_(params),
      scorer_(params.inlier_distance_ratio * static_cast<float>(geometry.block_size),
              static_cast<float>(geometry.block_size) * 1.5f) {
  points_.reserve(static_cast<std::size_t>(geometry.capacity));
  failed_at_.assign(static_cast<std::size_t>(geometry.block_count()), kNeverFailed);
}

int LineDetector::detect(const ScarfLattice& lattice, LineMap& lines, Timestamp now) {
  const float b = static_cast<float>(geometry_.block_size);
  const float capacity = static_cast<float>(geometry_.capacity);
  int created = 0;
  if (lattice.versions_of() != versions_of_) {  // another lattice: its versions mean nothing here
    versions_of_ = lattice.versions_of();
    std::fill(failed_at_.begin(), failed_at_.end(), kNeverFailed);
  }
  for (int block = 0; block < geometry_.block_count(); ++block) {
    const BlockStatus status = lines.block_status(block);
    if (status == BlockStatus::ProhibitDetection) {
      lines.set_block_status(block, BlockStatus::NoDetect);  // suppression lasts one round
      continue;
    }
    if (status != BlockStatus::NoDetect || lattice.active_count(block) < geometry_.min_points()) continue;
    const std::uint64_t version = lattice.version(block);
    if (failed_at_[block] == version) continue;
    failed_at_[block] = version;  // until it succeeds below
    points_.clear();
    points_.add(lattice.entries(block), /*include_inactive=*/false);
    const auto line = fit_line(points_, params_.fit_iterations);
    if (!line) continue;
    const int i = geometry_.column(block), j = geometry_.row(block);
    const auto segment = clip_to_square(*line, geometry_.origin_x(i), geometry_.origin_y(j), b);
    if (!segment) continue;
    const float f = scorer_.score(*segment, points_, capacity).score();
    if (f > params_.fit_threshold) {
      lines.add(*segment, f, block, now);
      failed_at_[block] = kNeverFailed;
      ++created;
    }
  }
  return created;
}

}  // namespace evldt
