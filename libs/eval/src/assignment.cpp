#include "evldt/eval/assignment.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>
#include <utility>

namespace evldt {

namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

}  // namespace

std::vector<std::size_t> max_weight_matching(std::size_t rows, std::size_t columns,
                                             std::span<const WeightedPair> pairs) {
  for (const WeightedPair& p : pairs) {
    if (p.row >= rows || p.column >= columns) {
      throw std::invalid_argument("pair (" + std::to_string(p.row) + ", " + std::to_string(p.column) +
                                  ") is outside a " + std::to_string(rows) + " x " + std::to_string(columns) +
                                  " graph");
    }
    if (!std::isfinite(p.weight) || p.weight <= 0) {
      throw std::invalid_argument("pair weights must be finite and > 0, got " + std::to_string(p.weight));
    }
  }
  // Minimum cost with cost = -weight. Edge e < pairs.size() is a pair; edge pairs.size() + r is row r's
  // "unmatched" option, a private column (columns + r) at cost 0, so every row can be assigned.
  const std::size_t real_edges = pairs.size();
  const std::size_t all_columns = columns + rows;
  const auto column_of = [&](std::size_t e) { return e < real_edges ? pairs[e].column : columns + (e - real_edges); };
  const auto cost_of = [&](std::size_t e) { return e < real_edges ? -pairs[e].weight : 0.0; };

  // Edges by row (counting sort, stable), each row's unmatched option last.
  std::vector<std::size_t> first_edge(rows + 1, 0);
  for (const WeightedPair& p : pairs) ++first_edge[p.row + 1];
  for (std::size_t r = 0; r < rows; ++r) first_edge[r + 1] += first_edge[r] + 1;
  std::vector<std::size_t> edges(real_edges + rows);
  {
    std::vector<std::size_t> fill(first_edge.begin(), first_edge.end() - 1);
    for (std::size_t e = 0; e < real_edges; ++e) edges[fill[pairs[e].row]++] = e;
    for (std::size_t r = 0; r < rows; ++r) edges[fill[r]] = real_edges + r;
  }

  // Potentials keep every reduced cost cost(e) - row_potential[r] - column_potential[c] of the rows
  // started so far >= 0, and 0 on matched edges, so Dijkstra finds shortest augmenting paths. Free
  // columns keep potential 0 (only settled columns change, and those end matched), so the distances
  // of different free columns compare as path costs.
  std::vector<double> column_potential(all_columns, 0.0), row_potential(rows, 0.0);
  std::vector<std::size_t> row_of_column(all_columns, kNone), edge_of_row(rows, kNone);
  std::vector<double> distance(all_columns, std::numeric_limits<double>::infinity());
  std::vector<std::size_t> reached_by(all_columns, kNone);  // edge that last improved the column's distance
  std::vector<bool> settled(all_columns, false);
  std::vector<std::size_t> touched, settled_columns;
  using Entry = std::pair<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;

  const auto reduced = [&](std::size_t e, std::size_t r) {
    return cost_of(e) - row_potential[r] - column_potential[column_of(e)];
  };
  const auto relax_from = [&](std::size_t r, double base) {
    for (std::size_t k = first_edge[r]; k < first_edge[r + 1]; ++k) {
      const std::size_t e = edges[k], c = column_of(e);
      if (settled[c]) continue;
      const double d = base + reduced(e, r);
      if (d < distance[c]) {
        if (distance[c] == std::numeric_limits<double>::infinity()) touched.push_back(c);
        distance[c] = d;
        reached_by[c] = e;
        queue.push({d, c});
      }
    }
  };
  const auto row_of_edge = [&](std::size_t e) { return e < real_edges ? pairs[e].row : e - real_edges; };

  for (std::size_t start = 0; start < rows; ++start) {
    // A new row's potential makes its cheapest edge tight.
    double cheapest = std::numeric_limits<double>::infinity();
    for (std::size_t k = first_edge[start]; k < first_edge[start + 1]; ++k) {
      const std::size_t e = edges[k];
      cheapest = std::min(cheapest, cost_of(e) - column_potential[column_of(e)]);
    }
    row_potential[start] = cheapest;
    relax_from(start, 0.0);
    std::size_t free_column = kNone;
    while (!queue.empty()) {
      const auto [d, c] = queue.top();
      queue.pop();
      if (settled[c] || d > distance[c]) continue;
      settled[c] = true;
      settled_columns.push_back(c);
      if (row_of_column[c] == kNone) {
        free_column = c;
        break;
      }
      relax_from(row_of_column[c], d);
    }
    // The row's own unmatched option is always reachable, so a free column is always found.
    const double path = distance[free_column];
    for (const std::size_t c : settled_columns) column_potential[c] += distance[c] - path;
    for (std::size_t c = free_column;;) {
      const std::size_t e = reached_by[c], r = row_of_edge(e);
      const std::size_t previous = edge_of_row[r] == kNone ? kNone : column_of(edge_of_row[r]);
      row_of_column[c] = r;
      edge_of_row[r] = e;
      if (r == start) break;
      c = previous;
    }
    for (const std::size_t c : settled_columns) {
      const std::size_t r = row_of_column[c];
      if (r != kNone) row_potential[r] = cost_of(edge_of_row[r]) - column_potential[c];
    }
    row_potential[start] = cost_of(edge_of_row[start]) - column_potential[column_of(edge_of_row[start])];
    for (const std::size_t c : touched) {
      distance[c] = std::numeric_limits<double>::infinity();
      settled[c] = false;
    }
    touched.clear();
    settled_columns.clear();
    queue = {};
  }

  std::vector<std::size_t> chosen;
  for (std::size_t r = 0; r < rows; ++r) {
    if (edge_of_row[r] < real_edges) chosen.push_back(edge_of_row[r]);
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

}  // namespace evldt
