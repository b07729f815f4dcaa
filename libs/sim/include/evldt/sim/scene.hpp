#pragma once
// A simulated scene: convex shapes of constant brightness, painted in order over a background,
// each moved by its own motion composed with a camera motion (homographies, so boxes can turn and
// tilt as under 6-DoF motion). Straight-edged shapes give ground-truth segments; curved ones
// (polygonised circles) only occlude.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt {

using Vec2d = Eigen::Vector2d;

/// One motion parameter over time: base + rate * t + amplitude * sin(2 pi frequency t + phase), t in s.
struct MotionChannel {
  double base = 0, rate = 0, amplitude = 0, frequency_hz = 0, phase = 0;
  [[nodiscard]] double at(double t) const;
};

/// Image-plane motion about a pivot: translate, rotate (rad), scale (log), and perspective terms (1/px).
struct Motion {
  MotionChannel tx, ty, angle, log_scale, perspective_x, perspective_y;
  Vec2d pivot = Vec2d::Zero();
  [[nodiscard]] Eigen::Matrix3d homography(double t) const;
};

/// A light that switches between full and `low` times its brightness, as mains lights (100/120 Hz)
/// and LED PWM do: on from k / hz for duty / hz, then low. hz 0: steady.
struct Flicker {
  double hz = 0;
  double duty = 0.5;
  double low = 0.5;
  /// The brightness factor at time t_us: 1 from on_us(k) until off_us(k), else low.
  [[nodiscard]] double factor_at(Timestamp t_us) const;
  /// The first time after `after_us` at which the light switches; a steady light never does.
  [[nodiscard]] Timestamp next_switch_us(Timestamp after_us) const;
  /// Switching times of cycle k, whole us (rounded up, the same for both functions above).
  [[nodiscard]] Timestamp on_us(double k) const;
  [[nodiscard]] Timestamp off_us(double k) const;
};

struct Shape {
  std::vector<Vec2d> polygon;  ///< convex, in image coordinates at rest
  double brightness = 0.5;     ///< linear intensity in (0, 1]
  bool straight_edges = true;  ///< its edges are ground-truth lines
  Motion motion;
  Flicker flicker;
};

/// A visible piece of a straight edge at one time.
struct GtSegment {
  int gt_id = 0;  ///< shape index * 64 + edge index
  Vec2d a, b;
};

struct Scene {
  std::string name;
  SensorSize sensor;
  double background = 0.5;
  Motion camera;
  std::vector<Shape> shapes;
  Timestamp duration_us = 1'000'000;

  /// Shape polygon at time t (camera and own motion applied).
  [[nodiscard]] std::vector<Vec2d> polygon_at(std::size_t shape, double t) const;
  /// Visible straight edges at time t: clipped to the sensor and to the parts not covered by a shape
  /// painted later, pieces shorter than min_length_px dropped.
  [[nodiscard]] std::vector<GtSegment> visible_edges(Timestamp t_us, double min_length_px = 2.0) const;
};

}  // namespace evldt
