#include "evldt/lines/line_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace evldt {

namespace {

// Fair M-estimator scale, as in OpenCV's fitLine(DIST_FAIR).
constexpr float kFairScale = 1.3998f;

struct Moments {
  double w = 0, x = 0, y = 0, xx = 0, xy = 0, yy = 0;
  void add(double px, double py, double weight) {
    w += weight;
    x += weight * px;
    y += weight * py;
    xx += weight * px * px;
    xy += weight * px * py;
    yy += weight * py * py;
  }
  // Principal axis of the weighted scatter; false when it is undefined.
  bool line(InfiniteLine& out) const {
    if (w <= 0) return false;
    const double mx = x / w, my = y / w;
    const double sxx = xx / w - mx * mx, sxy = xy / w - mx * my, syy = yy / w - my * my;
    if (sxx + syy < 1e-9) return false;
    const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
    out.point = Point2(static_cast<float>(mx), static_cast<float>(my));
    out.direction = Point2(static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)));
    return true;
  }
};

}  // namespace

std::optional<InfiniteLine> fit_line(const PointSet& points, int reweight_iterations) {
  const float* xs = points.x();
  const float* ys = points.y();
  const std::size_t n = points.size();
  Moments moments;
  for (std::size_t i = 0; i < n; ++i) moments.add(xs[i], ys[i], 1.0);
  InfiniteLine line;
  if (!moments.line(line)) return std::nullopt;
  // The weights of a chunk of points first, in a loop the compiler vectorises (the divisions would
  // otherwise hold up each point's sums); then the sums, in point order.
  constexpr std::size_t kChunk = 64;
  double weights[kChunk];
  for (int iteration = 0; iteration < reweight_iterations; ++iteration) {
    Moments weighted;
    const float px = line.point.x(), py = line.point.y(), dx = line.direction.x(), dy = line.direction.y();
    for (std::size_t begin = 0; begin < n; begin += kChunk) {
      const std::size_t count = std::min(kChunk, n - begin);
      for (std::size_t i = 0; i < count; ++i) {
        // cross2(p - point, direction), rounded as Point2 arithmetic would.
        const float ox = xs[begin + i] - px, oy = ys[begin + i] - py;
        const float residual = std::abs(ox * dy - oy * dx);
        weights[i] = 1.0 / (1.0 + residual / kFairScale);
      }
      for (std::size_t i = 0; i < count; ++i) weighted.add(xs[begin + i], ys[begin + i], weights[i]);
    }
    if (!weighted.line(line)) return std::nullopt;
  }
  return line;
}

std::optional<Segment> clip_to_square(const InfiniteLine& line, float x0, float y0, float size) {
  // Liang-Barsky on the parametric line p + t d.
  float t_min = -std::numeric_limits<float>::infinity();
  float t_max = std::numeric_limits<float>::infinity();
  const float lo[2] = {x0, y0};
  for (int axis = 0; axis < 2; ++axis) {
    const float p = line.point[axis];
    const float d = line.direction[axis];
    if (std::abs(d) < 1e-9f) {
      if (p < lo[axis] || p > lo[axis] + size) return std::nullopt;
      continue;
    }
    float t0 = (lo[axis] - p) / d;
    float t1 = (lo[axis] + size - p) / d;
    if (t0 > t1) std::swap(t0, t1);
    t_min = std::max(t_min, t0);
    t_max = std::min(t_max, t1);
  }
  if (!(t_max - t_min > 1e-4f)) return std::nullopt;
  Segment s{line.point + t_min * line.direction, line.point + t_max * line.direction};
  // Snap the coordinate that lies on the border exactly onto it, so endpoints sit on lattice lines.
  for (Point2* q : {&s.q0, &s.q1}) {
    for (int axis = 0; axis < 2; ++axis) {
      for (const float border : {lo[axis], lo[axis] + size}) {
        if (std::abs((*q)[axis] - border) < 1e-3f) (*q)[axis] = border;
      }
    }
  }
  return s;
}

}  // namespace evldt
