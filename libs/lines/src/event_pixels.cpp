#include "evldt/lines/event_pixels.hpp"

#include <algorithm>
#include <cmath>

namespace evldt {

void EventPixels::reset(const ScarfLattice* lattice) {
  for (const int block : mapped_blocks_) map_index_[static_cast<std::size_t>(block)] = -1;
  mapped_blocks_.clear();
  lattice_ = lattice;
  if (lattice == nullptr) return;
  const LatticeGeometry& geometry = lattice->geometry();
  block_size_ = geometry.block_size;
  map_index_.resize(static_cast<std::size_t>(geometry.block_count()), -1);
}

const std::uint8_t* EventPixels::map_of(int block) {
  const std::size_t extent = 2 * static_cast<std::size_t>(block_size_);
  std::int32_t& index = map_index_[static_cast<std::size_t>(block)];
  if (index < 0) {
    index = static_cast<std::int32_t>(mapped_blocks_.size());
    mapped_blocks_.push_back(block);
    // The memory of the largest step so far is kept: no allocation once steps are alike.
    if (maps_.size() < mapped_blocks_.size() * extent * extent) maps_.resize(mapped_blocks_.size() * extent * extent);
    std::uint8_t* map = maps_.data() + static_cast<std::size_t>(index) * extent * extent;
    std::fill(map, map + extent * extent, std::uint8_t{0});
    for (const LatticeEntry e : lattice_->entries(block).entries) {
      map[static_cast<std::size_t>(e.dy()) * extent + static_cast<std::size_t>(e.dx())] = 1;
    }
  }
  return maps_.data() + static_cast<std::size_t>(index) * extent * extent;
}

bool EventPixels::any_within(Point2 at, float radius) {
  if (lattice_ == nullptr) return false;
  const int block = lattice_->geometry().block_at(at.x(), at.y());
  if (block < 0) return false;
  const std::uint8_t* map = map_of(block);
  const BlockEntries region = lattice_->entries(block);
  const int extent = 2 * block_size_;
  // In the region's own pixels: `at` lies in the active region, b/2 inside the extended one on every
  // side, so a radius of b/2 stays in the map (the bounds guard it all the same).
  const float x = at.x() - static_cast<float>(region.origin_x), y = at.y() - static_cast<float>(region.origin_y);
  const float r = std::min(radius, 0.5f * static_cast<float>(block_size_));
  const float r_squared = r * r;
  const int y0 = std::max(0, static_cast<int>(std::ceil(y - r))),
            y1 = std::min(extent - 1, static_cast<int>(std::floor(y + r)));
  const int x0 = std::max(0, static_cast<int>(std::ceil(x - r))),
            x1 = std::min(extent - 1, static_cast<int>(std::floor(x + r)));
  for (int py = y0; py <= y1; ++py) {
    const float dy = static_cast<float>(py) - y;
    const std::uint8_t* row = map + static_cast<std::size_t>(py) * static_cast<std::size_t>(extent);
    for (int px = x0; px <= x1; ++px) {
      const float dx = static_cast<float>(px) - x;
      if (row[px] != 0 && dx * dx + dy * dy <= r_squared) return true;
    }
  }
  return false;
}

}  // namespace evldt
