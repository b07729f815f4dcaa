#include "evldt/pipeline/whole_line_stage.hpp"

namespace evldt {

WholeLineStage::WholeLineStage(const PipelineConfig& config, std::uint64_t first_id)
    : tracker_(config.lattice.block_size, config.whole_lines, first_id) {}

std::span<const TrackedLine> WholeLineStage::step(Timestamp t, std::span<const TrackedLine> segments,
                                                  const ScarfLattice* lattice) {
  tracker_.update(t, segments, lattice);
  lines_.clear();
  for (const WholeLine& line : tracker_.lines()) {
    lines_.push_back({.id = line.id,
                      .segment = line.segment,
                      .score = static_cast<float>(line.segments),
                      .status = LineStatus::GoodTrack,
                      .admin_block = -1,
                      .first_seen_us = line.first_seen_us,
                      .last_good_us = line.last_seen_us,
                      .normal_velocity = line.normal_velocity,
                      .normal_velocity_std = line.normal_velocity_std});
  }
  return lines_;
}

}  // namespace evldt
