#include "evldt/eval/whole_line_support.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace evldt {
namespace {

float distance_to_segment(const Point2& p, const Segment& s) {
  const Point2 d = s.q1 - s.q0;
  const float length_sq = d.squaredNorm();
  const float along = length_sq > 0 ? std::clamp((p - s.q0).dot(d) / length_sq, 0.0f, 1.0f) : 0.0f;
  return (p - (s.q0 + along * d)).norm();
}

}  // namespace

WholeLineSupport::WholeLineSupport(float distance_px, float weak_below)
    : distance_px_(distance_px), weak_below_(weak_below) {
  if (!(distance_px >= 0) || !(weak_below >= 0 && weak_below <= 1)) {
    throw std::invalid_argument("support distance must be >= 0 and the weak share in 0..1");
  }
}

void WholeLineSupport::add_step(std::span<const Segment> whole_lines, std::span<const Segment> segments) {
  ++totals_.steps;
  for (const Segment& line : whole_lines) {
    const float length = line.length();
    // Points 1 px apart or closer, each standing for an equal piece of the line.
    const int pieces = std::max(1, static_cast<int>(std::ceil(length)));
    const Point2 low = line.q0.cwiseMin(line.q1).array() - distance_px_;
    const Point2 high = line.q0.cwiseMax(line.q1).array() + distance_px_;
    near_.clear();
    for (std::uint32_t s = 0; s < segments.size(); ++s) {
      const Point2 s_low = segments[s].q0.cwiseMin(segments[s].q1), s_high = segments[s].q0.cwiseMax(segments[s].q1);
      if ((s_low.array() <= high.array()).all() && (s_high.array() >= low.array()).all()) near_.push_back(s);
    }
    int supported = 0;
    for (int k = 0; k < pieces; ++k) {
      const Point2 p = line.q0 + (static_cast<float>(k) + 0.5f) / static_cast<float>(pieces) * (line.q1 - line.q0);
      supported += std::any_of(near_.begin(), near_.end(),
                               [&](std::uint32_t s) { return distance_to_segment(p, segments[s]) <= distance_px_; });
    }
    const double share = static_cast<double>(supported) / pieces;
    ++totals_.lines;
    totals_.length_px += length;
    supported_px_ += share * length;
    if (share < weak_below_) ++totals_.weak_lines;
  }
}

SupportSummary WholeLineSupport::summary() const {
  SupportSummary s = totals_;
  constexpr double kUndefined = std::numeric_limits<double>::quiet_NaN();  // no lines: no share
  s.supported_share = s.length_px > 0 ? supported_px_ / s.length_px : kUndefined;
  s.weak_share = s.lines > 0 ? static_cast<double>(s.weak_lines) / static_cast<double>(s.lines) : kUndefined;
  return s;
}

}  // namespace evldt
