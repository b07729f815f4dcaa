#include "evldt/lines/normal_motion.hpp"

namespace evldt {

namespace {
constexpr double kSecondsPerUs = 1e-6;
}  // namespace

Point2 unit_normal(const Segment& segment) {
  const Point2 along = segment.q1 - segment.q0;
  const float length = along.norm();
  if (!(length > 0)) return Point2::Zero();
  return Point2(-along.y(), along.x()) / length;
}

void start_motion(NormalMotion& motion, const Segment& segment, Timestamp t_us, const MotionParams& params) {
  const float position_var = params.position_std_px * params.position_std_px;
  motion = {.anchor = segment.centre(),
            .normal = unit_normal(segment),
            .velocity = 0,
            .var_position = position_var,
            .covariance = 0,
            .var_velocity = params.initial_velocity_std * params.initial_velocity_std,
            .t_us = t_us,
            .started = true};
}

void observe_motion(NormalMotion& motion, const Segment& segment, Point2 at, Timestamp t_us,
                    const MotionParams& params) {
  Point2 n = unit_normal(segment);
  if (!motion.started || n.isZero()) {
    if (!n.isZero()) start_motion(motion, segment, t_us, params);
    return;
  }
  // The velocity is along the line's own normal: one drawn the other way round has the opposite one.
  if (n.dot(motion.normal) < 0) {
    motion.velocity = -motion.velocity;
    motion.covariance = -motion.covariance;
  }
  const double dt = static_cast<double>(t_us - motion.t_us) * kSecondsPerUs;
  if (dt <= 0) return;
  // Predict: constant velocity, white-noise acceleration of spectral density q.
  const double acceleration =
      static_cast<double>(params.acceleration_noise) + params.acceleration_noise_per_speed * std::abs(motion.velocity);
  const double q = acceleration * acceleration;
  const double v = motion.velocity;
  double pdd = motion.var_position, pdv = motion.covariance, pvv = motion.var_velocity;
  const double predicted = v * dt;
  pdd += dt * (2 * pdv + dt * pvv) + q * dt * dt * dt / 3;
  pdv += dt * pvv + q * dt * dt / 2;
  pvv += q * dt;
  // Update with where the line is now along its normal, from the last estimate.
  const double measured = n.dot(at - motion.anchor);
  const double r = static_cast<double>(params.position_std_px) * params.position_std_px;
  const double innovation = measured - predicted, s = pdd + r;
  const double gain_position = pdd / s, gain_velocity = pdv / s;
  const double position = predicted + gain_position * innovation;
  motion.velocity = static_cast<float>(v + gain_velocity * innovation);
  motion.var_velocity = static_cast<float>(pvv - gain_velocity * pdv);
  motion.covariance = static_cast<float>((1 - gain_position) * pdv);
  motion.var_position = static_cast<float>((1 - gain_position) * pdd);
  motion.anchor = at - static_cast<float>(measured - position) * n;
  motion.normal = n;
  motion.t_us = t_us;
}

}  // namespace evldt
