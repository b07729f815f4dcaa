#pragma once
// The test oracle of the heat-map matcher: the BSDS benchmark's min-cost assignment, solved exactly.

#include <cstdint>
#include <span>

#include "evldt/eval/line_heatmap.hpp"

namespace evldt {

/// Most pixels per side that min_cost_matched_count_reference accepts (its cost is cubic).
inline constexpr std::size_t kReferenceMaxPixels = 600;

/// Test reference, for small scenes only: rasterises like HeatmapMatcher and solves the BSDS-style
/// assignment, where a pair within tolerance costs its distance, an unmatched pixel costs
/// outlier_cost_factor * tolerance and pairs beyond tolerance are not allowed, exactly with the
/// Hungarian algorithm; returns the number of pairs. Throws std::length_error above
/// kReferenceMaxPixels pixels per side.
[[nodiscard]] std::uint64_t min_cost_matched_count_reference(SensorSize sensor, double tolerance_fraction,
                                                             std::span<const Segment> predicted,
                                                             std::span<const Segment> ground_truth,
                                                             double outlier_cost_factor = 100.0);

}  // namespace evldt
