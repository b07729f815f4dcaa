#include "evldt/lines/point_set.hpp"

namespace evldt {

void PointSet::add(std::span<const LatticeEntry> entries, bool include_inactive) {
  // Branch-free compaction: whether an entry is active is data, and a branch on it mispredicts.
  std::size_t n = x_.size();
  x_.resize(n + entries.size());
  y_.resize(n + entries.size());
  for (const LatticeEntry& e : entries) {
    x_[n] = e.cx();
    y_[n] = e.cy();
    n += static_cast<std::size_t>(include_inactive | e.active());
  }
  x_.resize(n);
  y_.resize(n);
}

}  // namespace evldt
