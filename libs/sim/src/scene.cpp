#include "evldt/sim/scene.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace evldt {

double MotionChannel::at(double t) const {
  return base + rate * t + amplitude * std::sin(6.283185307179586 * frequency_hz * t + phase);
}

Timestamp Flicker::on_us(double k) const { return static_cast<Timestamp>(std::ceil(k / hz * 1e6)); }
Timestamp Flicker::off_us(double k) const { return static_cast<Timestamp>(std::ceil((k + duty) / hz * 1e6)); }

double Flicker::factor_at(Timestamp t_us) const {
  if (hz <= 0) return 1.0;
  // The cycle t_us falls in, by the same rounded switching times next_switch_us gives.
  double k = std::floor(static_cast<double>(t_us) * 1e-6 * hz);
  if (t_us < on_us(k)) k -= 1;
  if (t_us >= on_us(k + 1)) k += 1;
  return t_us < off_us(k) ? 1.0 : low;
}

Timestamp Flicker::next_switch_us(Timestamp after_us) const {
  if (hz <= 0) return std::numeric_limits<Timestamp>::max();
  const double k = std::floor(static_cast<double>(after_us) * 1e-6 * hz);
  for (const Timestamp at : {off_us(k - 1), on_us(k), off_us(k), on_us(k + 1), off_us(k + 1)}) {
    if (at > after_us) return at;
  }
  return after_us + 1;  // not reached: cycle k + 1 ends later
}

Eigen::Matrix3d Motion::homography(double t) const {
  const double c = std::cos(angle.at(t)), s = std::sin(angle.at(t));
  const double k = std::exp(log_scale.at(t));
  Eigen::Matrix3d to_pivot = Eigen::Matrix3d::Identity();
  to_pivot(0, 2) = -pivot.x();
  to_pivot(1, 2) = -pivot.y();
  Eigen::Matrix3d perspective = Eigen::Matrix3d::Identity();
  perspective(2, 0) = perspective_x.at(t);
  perspective(2, 1) = perspective_y.at(t);
  Eigen::Matrix3d rotate_scale = Eigen::Matrix3d::Identity();
  rotate_scale << k * c, -k * s, 0, k * s, k * c, 0, 0, 0, 1;
  Eigen::Matrix3d back = Eigen::Matrix3d::Identity();
  back(0, 2) = pivot.x() + tx.at(t);
  back(1, 2) = pivot.y() + ty.at(t);
  return back * rotate_scale * perspective * to_pivot;
}

std::vector<Vec2d> Scene::polygon_at(std::size_t shape, double t) const {
  const Eigen::Matrix3d h = camera.homography(t) * shapes[shape].motion.homography(t);
  std::vector<Vec2d> out;
  out.reserve(shapes[shape].polygon.size());
  for (const Vec2d& v : shapes[shape].polygon) {
    const Eigen::Vector3d p = h * Eigen::Vector3d(v.x(), v.y(), 1.0);
    out.emplace_back(p.x() / p.z(), p.y() / p.z());
  }
  return out;
}

namespace {

using Interval = std::pair<double, double>;

// Parameter interval of a + u (b - a), u in [0, 1], inside the convex polygon; empty if first >= second.
Interval inside_convex(const Vec2d& a, const Vec2d& b, const std::vector<Vec2d>& polygon) {
  double area = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Vec2d& p = polygon[i];
    const Vec2d& q = polygon[(i + 1) % polygon.size()];
    area += p.x() * q.y() - q.x() * p.y();
  }
  const double orientation = area >= 0 ? 1.0 : -1.0;
  double lo = 0.0, hi = 1.0;
  const Vec2d d = b - a;
  for (std::size_t i = 0; i < polygon.size() && lo < hi; ++i) {
    const Vec2d& p = polygon[i];
    const Vec2d edge = polygon[(i + 1) % polygon.size()] - p;
    const Vec2d inward = orientation * Vec2d(-edge.y(), edge.x());  // points into the polygon
    const double num = inward.dot(a - p);                           // >= 0 inside this half-plane at u = 0
    const double den = inward.dot(d);
    if (std::abs(den) < 1e-12) {
      if (num < 0) return {1.0, 0.0};
      continue;
    }
    const double u = -num / den;
    if (den > 0)
      lo = std::max(lo, u);
    else
      hi = std::min(hi, u);
  }
  return {lo, hi};
}

}  // namespace

std::vector<GtSegment> Scene::visible_edges(Timestamp t_us, double min_length_px) const {
  const double t = static_cast<double>(t_us) * 1e-6;
  std::vector<std::vector<Vec2d>> polygons;
  for (std::size_t k = 0; k < shapes.size(); ++k) polygons.push_back(polygon_at(k, t));
  const std::vector<Vec2d> frame{{0, 0},
                                 {static_cast<double>(sensor.width), 0},
                                 {static_cast<double>(sensor.width), static_cast<double>(sensor.height)},
                                 {0, static_cast<double>(sensor.height)}};
  std::vector<GtSegment> out;
  std::vector<Interval> hidden;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    if (!shapes[k].straight_edges) continue;
    const auto& polygon = polygons[k];
    for (std::size_t e = 0; e < polygon.size(); ++e) {
      const Vec2d a = polygon[e], b = polygon[(e + 1) % polygon.size()];
      const double length = (b - a).norm();
      const Interval on_sensor = inside_convex(a, b, frame);
      if (on_sensor.first >= on_sensor.second) continue;
      hidden.clear();
      for (std::size_t j = k + 1; j < shapes.size(); ++j) {
        const Interval covered = inside_convex(a, b, polygons[j]);
        if (covered.first < covered.second) hidden.push_back(covered);
      }
      std::sort(hidden.begin(), hidden.end());
      double from = on_sensor.first;
      auto emit = [&](double u0, double u1) {
        if ((u1 - u0) * length >= min_length_px) {
          out.push_back({static_cast<int>(k * 64 + e), a + u0 * (b - a), a + u1 * (b - a)});
        }
      };
      for (const Interval& h : hidden) {
        if (h.first > from) emit(from, std::min(h.first, on_sensor.second));
        from = std::max(from, h.second);
        if (from >= on_sensor.second) break;
      }
      if (from < on_sensor.second) emit(from, on_sensor.second);
    }
  }
  return out;
}

}  // namespace evldt
