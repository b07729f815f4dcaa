#pragma once
// The points a line is fitted to and scored on, gathered from lattice entries once per block or line.

#include <cstddef>
#include <span>
#include <vector>

#include "evldt/scarf/scarf_lattice.hpp"

namespace evldt {

/// Pixel centres as structure-of-arrays, gathered once per block or line and then fitted and scored
/// for every hypothesis (the inner loops read two float arrays, no flags).
class PointSet {
 public:
  void reserve(std::size_t n) {
    x_.reserve(n);
    y_.reserve(n);
  }
  void clear() {
    x_.clear();
    y_.clear();
  }
  /// Adds the centres of the ACTIVE entries, and of the inactive ones too when include_inactive is set.
  void add(const BlockEntries& block, bool include_inactive);
  [[nodiscard]] std::size_t size() const { return x_.size(); }
  [[nodiscard]] const float* x() const { return x_.data(); }
  [[nodiscard]] const float* y() const { return y_.data(); }

 private:
  std::vector<float> x_, y_;
};

}  // namespace evldt
