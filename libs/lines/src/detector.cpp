#include "evldt/lines/detector.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "evldt/lines/line_fit.hpp"

namespace evldt {

namespace {
constexpr std::uint64_t kNeverFailed = UINT64_MAX;
}  // namespace

LineDetector::LineDetector(const LatticeGeometry& geometry, const ScoreParams& params, RoundWorkers* workers)
    : geometry_(geometry),
      params_(params),
      round_workers_(workers),
      retry_after_(static_cast<std::uint16_t>(
          std::clamp(std::floor(params.retry_share * static_cast<float>(geometry.capacity)), 0.0f, 65535.0f))) {
  const int threads = workers ? workers->threads() : 1;
  const float b = static_cast<float>(geometry.block_size);
  workers_.reserve(static_cast<std::size_t>(threads));
  for (int w = 0; w < threads; ++w) {
    Worker& worker = workers_.emplace_back(Worker{
        FittingScorer(params.inlier_distance_ratio * b, b * 1.5f), BendTest(geometry, params.max_bend_ratio), {}});
    worker.points.reserve(static_cast<std::size_t>(geometry.capacity));
  }
  failed_at_.assign(static_cast<std::size_t>(geometry.block_count()), kNeverFailed);
  failed_arrivals_.assign(static_cast<std::size_t>(geometry.block_count()), 0);
  found_.resize(static_cast<std::size_t>(geometry.block_count()));
}

int LineDetector::detect(const ScarfLattice& lattice, LineMap& lines, Timestamp now, bool test_bends) {
  if (lattice.versions_of() != versions_of_) {  // another lattice: its versions mean nothing here
    versions_of_ = lattice.versions_of();
    std::fill(failed_at_.begin(), failed_at_.end(), kNeverFailed);
  }
  std::atomic<int> next_row{0};  // the next row a worker claims
  auto detect_claimed = [&](int w) {
    Worker& worker = workers_[static_cast<std::size_t>(w)];
    for (int row = next_row.fetch_add(1, std::memory_order_relaxed); row < geometry_.blocks_y;
         row = next_row.fetch_add(1, std::memory_order_relaxed)) {
      detect_row(lattice, lines, row, worker, test_bends);
    }
  };
  if (round_workers_ != nullptr && geometry_.block_count() >= kMinBlocksToSplit) {
    round_workers_->run(detect_claimed);
  } else {
    detect_claimed(0);
  }
  // Lines are created in block order: a new line may take over the id of a line released nearby,
  // and of two candidates the first block's wins, whatever worker found it.
  int created = 0;
  for (int block = 0; block < geometry_.block_count(); ++block) {
    Found& found = found_[static_cast<std::size_t>(block)];
    if (!found.present) continue;
    found.present = false;
    lines.add(found.segment, found.score, block, now);
    ++created;
  }
  return created;
}

void LineDetector::detect_row(const ScarfLattice& lattice, LineMap& lines, int row, Worker& worker, bool test_bends) {
  const float b = static_cast<float>(geometry_.block_size);
  const float capacity = static_cast<float>(geometry_.capacity);
  for (int column = 0; column < geometry_.blocks_x; ++column) {
    const int block = geometry_.index(column, row);
    const BlockStatus status = lines.block_status(block);
    if (status == BlockStatus::ProhibitDetection) {
      lines.set_block_status(block, BlockStatus::NoDetect);  // suppression lasts one round
      continue;
    }
    const int active = lattice.active_count(block);
    if (status != BlockStatus::NoDetect || active < geometry_.min_points()) continue;
    // f = r_o * r_e <= r_e <= active / N (r_o <= 1, inliers <= active): a block this sparse cannot
    // clear f_th, so its fit is skipped; the same comparison in floats, so skipping is exact.
    if (static_cast<float>(active) / capacity <= params_.fit_threshold) continue;
    const std::uint64_t version = lattice.version(block);
    const std::uint16_t arrivals = lattice.active_arrivals(block);
    if (failed_at_[block] == version) continue;
    if (failed_at_[block] != kNeverFailed &&
        static_cast<std::uint16_t>(arrivals - failed_arrivals_[block]) < retry_after_)
      continue;
    failed_at_[block] = version;  // until it succeeds below
    failed_arrivals_[block] = arrivals;
    worker.points.clear();
    worker.points.add(lattice.entries(block), /*include_inactive=*/false);
    const auto line = fit_line(worker.points, params_.fit_iterations);
    if (!line) continue;
    const auto segment = clip_to_square(*line, geometry_.origin_x(column), geometry_.origin_y(row), b);
    if (!segment) continue;
    const float f = worker.scorer.score(*segment, worker.points, capacity).score();
    if (f > params_.fit_threshold && !(test_bends && worker.bend.bent(lattice, *segment))) {
      found_[static_cast<std::size_t>(block)] = {true, f, *segment};
      failed_at_[block] = kNeverFailed;
    }
  }
}

}  // namespace evldt
