#include "eval/reference_matching.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace evldt {

std::uint64_t min_cost_matched_count_reference(SensorSize sensor, double tolerance_fraction,
                                               std::span<const Segment> predicted,
                                               std::span<const Segment> ground_truth, double outlier_cost_factor) {
  std::vector<std::uint8_t> predicted_map, ground_truth_map;
  rasterise(predicted, sensor, predicted_map);
  rasterise(ground_truth, sensor, ground_truth_map);
  const auto pixels_of = [&](const std::vector<std::uint8_t>& map) {
    std::vector<std::uint32_t> pixels;
    for (std::size_t i = 0; i < map.size(); ++i) {
      if (map[i] != 0) pixels.push_back(static_cast<std::uint32_t>(i));
    }
    if (pixels.size() > kReferenceMaxPixels) {
      throw std::length_error("reference matching takes at most " + std::to_string(kReferenceMaxPixels) +
                              " pixels per side, got " + std::to_string(pixels.size()));
    }
    return pixels;
  };
  std::vector<std::uint32_t> rows = pixels_of(predicted_map), columns = pixels_of(ground_truth_map);
  if (rows.empty() || columns.empty()) return 0;
  if (rows.size() > columns.size()) std::swap(rows, columns);

  // With every pixel either paired or an outlier, a pair beyond tolerance is no better than two
  // outliers; costing it exactly 2 * outlier (and capping in-tolerance pairs there) turns the problem
  // into a rectangular assignment of all rows whose pairs cheaper than 2 * outlier are the matches.
  const double tolerance = diagonal_tolerance_px(sensor, tolerance_fraction);
  const double outlier_pair_cost = 2.0 * outlier_cost_factor * tolerance;
  const double tolerance_squared = tolerance * tolerance;  // the same test as HeatmapMatcher's
  const std::size_t width = sensor.width;
  const std::size_t n = rows.size(), m = columns.size();
  std::vector<double> cost(n * m);
  for (std::size_t row = 0; row < n; ++row) {
    for (std::size_t column = 0; column < m; ++column) {
      const double dx = static_cast<double>(rows[row] % width) - static_cast<double>(columns[column] % width);
      const double dy = static_cast<double>(rows[row] / width) - static_cast<double>(columns[column] / width);
      const double distance_squared = dx * dx + dy * dy;
      cost[row * m + column] = distance_squared <= tolerance_squared
                                   ? std::min(std::sqrt(distance_squared), outlier_pair_cost)
                                   : outlier_pair_cost;
    }
  }

  // Hungarian algorithm with row and column potentials (1-based; column 0 is a virtual start).
  const double infinity = std::numeric_limits<double>::infinity();
  std::vector<double> row_potential(n + 1, 0), column_potential(m + 1, 0), slack(m + 1);
  std::vector<std::size_t> row_of_column(m + 1, 0), previous_column(m + 1, 0);
  std::vector<bool> visited(m + 1);
  for (std::size_t row = 1; row <= n; ++row) {
    row_of_column[0] = row;
    std::size_t column = 0;
    std::fill(slack.begin(), slack.end(), infinity);
    std::fill(visited.begin(), visited.end(), false);
    do {
      visited[column] = true;
      const std::size_t current_row = row_of_column[column];
      double delta = infinity;
      std::size_t next_column = 0;
      for (std::size_t j = 1; j <= m; ++j) {
        if (visited[j]) continue;
        const double reduced = cost[(current_row - 1) * m + j - 1] - row_potential[current_row] - column_potential[j];
        if (reduced < slack[j]) {
          slack[j] = reduced;
          previous_column[j] = column;
        }
        if (slack[j] < delta) {
          delta = slack[j];
          next_column = j;
        }
      }
      for (std::size_t j = 0; j <= m; ++j) {
        if (visited[j]) {
          row_potential[row_of_column[j]] += delta;
          column_potential[j] -= delta;
        } else {
          slack[j] -= delta;
        }
      }
      column = next_column;
    } while (row_of_column[column] != 0);
    do {
      const std::size_t previous = previous_column[column];
      row_of_column[column] = row_of_column[previous];
      column = previous;
    } while (column != 0);
  }

  std::uint64_t matched = 0;
  for (std::size_t j = 1; j <= m; ++j) {
    if (row_of_column[j] != 0 && cost[(row_of_column[j] - 1) * m + j - 1] < outlier_pair_cost) ++matched;
  }
  return matched;
}

}  // namespace evldt
