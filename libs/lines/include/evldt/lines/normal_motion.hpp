#pragma once
// A line's motion across itself, estimated from where tracking puts it round after round: a
// constant-velocity Kalman filter on the line's position along its normal. The lattice keeps no
// event times (a ring holds places only), so the motion comes from the tracked positions, which
// tracking rounds sample every track period.
//
// Sign: the normal of a segment q0 -> q1 is (-(y1 - y0), x1 - x0) / length, so for a line drawn
// left to right a positive velocity moves it down the image (y grows downwards).

#include <cmath>

#include "evldt/events/event.hpp"
#include "evldt/lines/geometry.hpp"

namespace evldt {

/// Chosen on boxes-6dof, three-lines-fast and monitor-hd (docs/whole-lines.md, "Motion").
struct MotionParams {
  /// Spread of an observed position along the normal about the edge, px: the middle of a line's
  /// event band, which the ring's turnover moves about.
  float position_std_px = 0.5f;
  /// The edge's acceleration across itself, as white noise of this spectral density, px/s^2 per
  /// sqrt(Hz): how quickly the estimate follows a change of speed. It grows with the speed (by
  /// acceleration_noise_per_speed per px/s), since a camera that moves faster turns faster too:
  /// slow edges get a steady estimate, fast ones a prompt one.
  float acceleration_noise = 200.0f;
  float acceleration_noise_per_speed = 2.0f;
  /// Of the velocity before the first position is measured, px/s.
  float initial_velocity_std = 500.0f;
};

/// The filter's state; the line's own geometry gives the normal at each observation.
struct NormalMotion {
  Point2 anchor = Point2::Zero();  ///< the estimated position: a point on the estimated line
  Point2 normal = Point2::Zero();  ///< the unit normal the velocity is along (the last observation's)
  float velocity = 0;              ///< px/s along the normal of the line's q0 -> q1
  float var_position = 0, covariance = 0, var_velocity = 0;
  Timestamp t_us = 0;
  bool started = false;

  [[nodiscard]] float velocity_std() const { return std::sqrt(var_velocity); }
};

/// The unit normal of a segment q0 -> q1, (0, 0) for a point.
[[nodiscard]] Point2 unit_normal(const Segment& segment);

/// How far ahead a drawn motion arrow looks: it spans where the line's middle goes in this time.
inline constexpr float kMotionArrowSeconds = 0.1f;
/// The arrow drawn for a line's motion: from its middle to where that moves in kMotionArrowSeconds
/// at `normal_velocity` (a point for a still line).
[[nodiscard]] inline Segment motion_arrow(const Segment& line, float normal_velocity) {
  const Point2 from = line.centre();
  return {from, from + unit_normal(line) * (normal_velocity * kMotionArrowSeconds)};
}

/// Starts the estimate at a line's first position, with no velocity known (started = true).
void start_motion(NormalMotion& motion, const Segment& segment, Timestamp t_us, const MotionParams& params);
/// One observation of the line at t_us (after the last): `segment` gives its direction, `at` a point
/// on it (the middle of its event band). The line may turn: the velocity is along its current normal.
void observe_motion(NormalMotion& motion, const Segment& segment, Point2 at, Timestamp t_us,
                    const MotionParams& params);

}  // namespace evldt
