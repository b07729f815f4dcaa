#pragma once
// Planar geometry of line segments in continuous image coordinates (see scarf_lattice.hpp).

#include <Eigen/Core>
#include <cmath>

namespace evldt {

using Point2 = Eigen::Vector2f;

/// z component of the 3-D cross product of two plane vectors.
inline float cross2(const Point2& a, const Point2& b) { return a.x() * b.y() - a.y() * b.x(); }

struct Segment {
  Point2 q0 = Point2::Zero();
  Point2 q1 = Point2::Zero();

  [[nodiscard]] float length() const { return (q1 - q0).norm(); }
  [[nodiscard]] Point2 centre() const { return 0.5f * (q0 + q1); }
};

}  // namespace evldt
