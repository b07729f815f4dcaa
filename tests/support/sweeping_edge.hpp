#pragma once
// Exact events of a straight edge segment translating at constant velocity: every pixel whose centre
// the moving segment crosses fires once, at the crossing time. Small and exact, for unit tests.

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/lines/geometry.hpp"

namespace evldt::testing {

struct SweepingEdge {
  Point2 a;  ///< segment endpoints at time t_begin_us
  Point2 b;
  Point2 velocity_px_s;  ///< translation; its component along the edge normal must not be zero
  Timestamp t_begin_us = 0;
  Timestamp t_end_us = 0;
};

inline EventBatch sweep_events(const SweepingEdge& edge, SensorSize sensor) {
  const Point2 along = edge.b - edge.a;
  const float length = along.norm();
  const Point2 unit = along / length;
  const Point2 normal(-unit.y(), unit.x());
  const double normal_speed = edge.velocity_px_s.dot(normal);
  struct Fired {
    Timestamp t;
    std::uint16_t x, y;
  };
  std::vector<Fired> fired;
  for (int y = 0; y < sensor.height; ++y) {
    for (int x = 0; x < sensor.width; ++x) {
      const Point2 centre(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
      const Point2 offset = centre - edge.a;
      const double seconds = offset.dot(normal) / normal_speed;  // when the edge line reaches the centre
      const auto t = edge.t_begin_us + static_cast<Timestamp>(std::llround(seconds * 1e6));
      if (seconds < 0 || t >= edge.t_end_us) continue;
      const Point2 moved = offset - edge.velocity_px_s * static_cast<float>(seconds);
      const float position = moved.dot(unit);
      if (position < 0 || position > length) continue;
      fired.push_back({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y)});
    }
  }
  std::sort(fired.begin(), fired.end(),
            [](const Fired& l, const Fired& r) { return std::tie(l.t, l.y, l.x) < std::tie(r.t, r.y, r.x); });
  EventBatch batch;
  for (const Fired& f : fired) batch.push_back(f.t, f.x, f.y, 1);
  return batch;
}

}  // namespace evldt::testing
