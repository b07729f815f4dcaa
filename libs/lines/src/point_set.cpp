#include "evldt/lines/point_set.hpp"

namespace evldt {

void PointSet::add(const BlockEntries& block, bool include_inactive) {
  // Branch-free compaction: whether an entry is active is data, and a branch on it mispredicts.
  std::size_t n = x_.size();
  x_.resize(n + block.entries.size());
  y_.resize(n + block.entries.size());
  // Pixel centres: the block's origin plus half a pixel, then the entry's place.
  const float x0 = static_cast<float>(block.origin_x) + 0.5f, y0 = static_cast<float>(block.origin_y) + 0.5f;
  for (const LatticeEntry e : block.entries) {
    x_[n] = x0 + static_cast<float>(e.dx());
    y_[n] = y0 + static_cast<float>(e.dy());
    n += static_cast<std::size_t>(include_inactive | e.active());
  }
  x_.resize(n);
  y_.resize(n);
}

}  // namespace evldt
