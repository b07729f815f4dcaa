#pragma once
// Robust total-least-squares line fit (docs/design.md, section 4): PCA, then a few rounds of Fair-weighted PCA,
// the same M-estimator OpenCV's fitLine(DIST_FAIR) uses, so outliers of a block pull the line less.

#include <optional>

#include "evldt/lines/geometry.hpp"
#include "evldt/lines/point_set.hpp"

namespace evldt {

struct InfiniteLine {
  Point2 point;      ///< a point on the line (the weighted centroid)
  Point2 direction;  ///< unit direction
};

/// Fits the points; nullopt when they do not define a direction (fewer than 2 distinct pixels).
std::optional<InfiniteLine> fit_line(const PointSet& points, int reweight_iterations);

/// The two points where the line crosses the border of the axis-aligned square [x0, x0+size] x [y0, y0+size];
/// nullopt if it misses the square or only touches a corner.
std::optional<Segment> clip_to_square(const InfiniteLine& line, float x0, float y0, float size);

}  // namespace evldt
