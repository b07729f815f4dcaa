#pragma once
// Points bucketed into square cells, for "what lies near here" queries over a step's segment ends.
// A counting sort over the cells the points span: O(points + cells) to build, no search to query.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "evldt/lines/geometry.hpp"

namespace evldt {

class PointGrid {
 public:
  /// Buckets points[i] (item i) into cells of side `cell` (> 0); a cell keeps its items in order.
  /// Points beyond kMaxCells cells of the others share the border cells (found, if sooner).
  void build(float cell, std::span<const Point2> points) {
    cell_ = cell;
    float min_x = 0, min_y = 0, max_x = 0, max_y = 0;
    bool any = false;
    for (const Point2& p : points) {
      if (!p.allFinite()) continue;
      min_x = any ? std::min(min_x, p.x()) : p.x();
      min_y = any ? std::min(min_y, p.y()) : p.y();
      max_x = any ? std::max(max_x, p.x()) : p.x();
      max_y = any ? std::max(max_y, p.y()) : p.y();
      any = true;
    }
    origin_x_ = std::floor(min_x / cell);
    origin_y_ = std::floor(min_y / cell);
    columns_ = 1 + static_cast<int>(std::min(std::floor(max_x / cell) - origin_x_, kMaxCells - 1.0f));
    rows_ = 1 + static_cast<int>(std::min(std::floor(max_y / cell) - origin_y_, kMaxCells - 1.0f));
    start_.assign(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(rows_) + 1, 0);
    cell_of_item_.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const auto [cx, cy] = cell_xy(points[i]);
      cell_of_item_[i] = static_cast<std::uint32_t>(cy * columns_ + cx);
      ++start_[cell_of_item_[i] + 1];
    }
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    items_.resize(points.size());
    fill_.assign(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < points.size(); ++i) items_[fill_[cell_of_item_[i]]++] = static_cast<std::uint32_t>(i);
  }

  /// Calls visit(item) for each item in the 3 x 3 cells around p, row by row, each cell in order.
  template <typename Visit>
  void for_each_near(const Point2& p, Visit&& visit) const {
    const auto [cx, cy] = cell_xy(p);
    for (int y = std::max(0, cy - 1); y <= std::min(rows_ - 1, cy + 1); ++y) {
      for (int x = std::max(0, cx - 1); x <= std::min(columns_ - 1, cx + 1); ++x) {
        const std::size_t c =
            static_cast<std::size_t>(y) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(x);
        for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) visit(items_[k]);
      }
    }
  }

 private:
  static constexpr float kMaxCells = 1024;  // per side: a grid of 4 MB at most, whatever the points

  /// The cell holding p, clamped to the grid (NaN goes to the first cell, infinity to its border).
  [[nodiscard]] std::pair<int, int> cell_xy(const Point2& p) const {
    const auto clamp = [](float v, int count) {
      return v >= 0 ? static_cast<int>(std::min(v, static_cast<float>(count - 1))) : 0;
    };
    return {clamp(std::floor(p.x() / cell_) - origin_x_, columns_),
            clamp(std::floor(p.y() / cell_) - origin_y_, rows_)};
  }

  float cell_ = 1, origin_x_ = 0, origin_y_ = 0;
  int columns_ = 1, rows_ = 1;
  std::vector<std::uint32_t> start_, items_, cell_of_item_, fill_;
};

}  // namespace evldt
