#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "evldt/lines/point_grid.hpp"

namespace evldt {
namespace {

std::vector<std::uint32_t> near(const PointGrid& grid, const Point2& p) {
  std::vector<std::uint32_t> found;
  grid.for_each_near(p, [&](std::uint32_t item) { found.push_back(item); });
  return found;
}

TEST(PointGrid, FindsThePointsOfTheNineCellsAroundAPointInOrder) {
  // Cells of 10: (5, 5) is in cell (0, 0); (25, 5) in (2, 0); (15, 15) in (1, 1); (35, 5) in (3, 0);
  // (5, 45) in (0, 4).
  const std::vector<Point2> points = {{25, 5}, {5, 5}, {15, 15}, {35, 5}, {6, 6}, {5, 45}};
  PointGrid grid;
  grid.build(10, points);
  // Around (15, 5), cell (1, 0): cells x 0..2, y 0..1, row by row, each cell's items in order.
  EXPECT_EQ(near(grid, {15, 5}), (std::vector<std::uint32_t>{1, 4, 0, 2}));
  EXPECT_EQ(near(grid, {38, 8}), (std::vector<std::uint32_t>{0, 3}));
  EXPECT_TRUE(near(grid, {35, 35}).empty());
  // A query beyond the grid is clamped to its border, and finds what lies there.
  EXPECT_EQ(near(grid, {80, 5}), (std::vector<std::uint32_t>{0, 3}));
}

TEST(PointGrid, FarAndNonFinitePointsShareBorderCellsAndAreNotLost) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<Point2> points = {{0, 0}, {1e9f, 0}, {inf, 0}, {std::numeric_limits<float>::quiet_NaN(), 0}};
  PointGrid grid;
  grid.build(1, points);                                                 // 1024 cells wide at most, whatever the spread
  EXPECT_EQ(near(grid, {0, 0}), (std::vector<std::uint32_t>{0, 3}));     // NaN: the first cell
  EXPECT_EQ(near(grid, {1e9f, 0}), (std::vector<std::uint32_t>{1, 2}));  // infinity: the border on its side
  grid.build(1, {});
  EXPECT_TRUE(near(grid, {0, 0}).empty());
}

}  // namespace
}  // namespace evldt
