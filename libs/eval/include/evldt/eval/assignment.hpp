#pragma once
// Maximum-weight one-to-one matching on a sparse bipartite graph, e.g. predicted track ids to
// ground-truth line ids for IDF1, where each id overlaps only a few ids of the other side.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace evldt {

/// An allowed pair of a bipartite graph and what choosing it is worth.
struct WeightedPair {
  std::uint32_t row = 0;
  std::uint32_t column = 0;
  double weight = 0;  ///< finite and > 0
};

/// Chooses pairs, each row and each column at most once, so that their total weight is the largest
/// possible; returns the chosen pairs' positions in `pairs`, ascending. Exact: the Hungarian method
/// on the sparse graph (one shortest augmenting path per row, Dijkstra on reduced costs), where every
/// row may also stay unmatched at weight 0. Deterministic for a given input order. Throws
/// std::invalid_argument for a row or column out of range or a weight that is not finite and > 0.
[[nodiscard]] std::vector<std::size_t> max_weight_matching(std::size_t rows, std::size_t columns,
                                                           std::span<const WeightedPair> pairs);

}  // namespace evldt
