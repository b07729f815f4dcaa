#include "evldt/lines/bend_test.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "evldt/lines/tracker.hpp"

namespace evldt {

namespace {
constexpr float kBandRatio = 0.4f;     // of b: events this far across the segment are fitted
constexpr float kFairScale = 1.0f;     // px: robust weight 1 / (1 + |residual| / scale)
constexpr int kReweights = 3;
constexpr float kMinBendPx = 2.0f;     // px: pixel noise alone bends a fit over 3 blocks of 10 px this much
constexpr float kMaxTilt = 0.7f;       // |linear| / |quadratic| above this: one end lifted alone, a corner
constexpr float kOnStraight = 0.3f;    // px: an event this close to the segment's line continues it
constexpr float kMinStraight = 0.6f;   // share of an end's far bins holding such an event: it runs on straight
constexpr float kOnCurve = 1.5f;       // px: an event this close to the fitted curve follows it
constexpr float kMinOnCurve = 0.6f;    // share of each end's bins that must hold such an event
}  // namespace

BendTest::BendTest(const LatticeGeometry& geometry, float max_bend_ratio)
    : geometry_(geometry),
      min_bend_px_(max_bend_ratio > 0 ? std::max(max_bend_ratio * static_cast<float>(geometry.block_size), kMinBendPx)
                                      : 0.0f) {
  const auto longest_walk = static_cast<std::size_t>(geometry.blocks_x + geometry.blocks_y + 2);
  const auto most_points = longest_walk * static_cast<std::size_t>(geometry.capacity);
  cells_.reserve(longest_walk);
  points_.reserve(most_points);
  u_.reserve(most_points);
  v_.reserve(most_points);
  bins_.resize(static_cast<std::size_t>(2 * geometry.block_size));
}

bool BendTest::runs_on_straight(float length) {
  // Bins [0, far) cover [b/2, b) beyond q0, bins [far, 2 far) the same beyond q1.
  const int b = geometry_.block_size, near = b / 2, far = b - near;
  std::fill(bins_.begin(), bins_.end(), 0);
  for (std::size_t i = 0; i < u_.size(); ++i) {
    if (std::abs(v_[i]) > kOnStraight) continue;
    const float beyond = std::abs(u_[i]) - 0.5f * length;
    if (beyond < static_cast<float>(near) || beyond >= static_cast<float>(b)) continue;
    bins_[static_cast<std::size_t>(static_cast<int>(beyond) - near + (u_[i] > 0 ? far : 0))] = 1;
  }
  for (int end = 0; end < 2; ++end) {
    const auto first = bins_.begin() + end * far;
    if (static_cast<float>(std::count(first, first + far, 1)) >= kMinStraight * static_cast<float>(far)) return true;
  }
  return false;
}

bool BendTest::followed_beyond_both_ends(const Eigen::Vector3d& curve, float length, float half_span) {
  // Bins [0, b) cover [0, b) beyond q0, bins [b, 2 b) the same beyond q1.
  const int b = geometry_.block_size;
  std::fill(bins_.begin(), bins_.end(), 0);
  for (std::size_t i = 0; i < u_.size(); ++i) {
    const double u = u_[i] / half_span;
    if (std::abs(v_[i] - (curve[0] + curve[1] * u + curve[2] * u * u)) > kOnCurve) continue;
    const float beyond = std::abs(u_[i]) - 0.5f * length;
    if (beyond < 0 || beyond >= static_cast<float>(b)) continue;
    bins_[static_cast<std::size_t>(static_cast<int>(beyond) + (u_[i] > 0 ? b : 0))] = 1;
  }
  for (int end = 0; end < 2; ++end) {
    const auto first = bins_.begin() + end * b;
    if (static_cast<float>(std::count(first, first + b, 1)) < kMinOnCurve * static_cast<float>(b)) return false;
  }
  return true;
}

bool BendTest::bent(const ScarfLattice& lattice, const Segment& segment) {
  if (min_bend_px_ <= 0) return false;
  const float length = segment.length();
  if (!(length > 0)) return false;
  const auto b = static_cast<float>(geometry_.block_size);
  const Point2 unit = (segment.q1 - segment.q0) / length;
  const Point2 normal(-unit.y(), unit.x());
  const Point2 centre = 0.5f * (segment.q0 + segment.q1);
  const float half_span = 0.5f * length + b;
  cells_.clear();
  blocks_along({segment.q0 - b * unit, segment.q1 + b * unit}, geometry_, cells_);
  points_.clear();
  for (const int cell : cells_) points_.add(lattice.entries(cell), /*include_inactive=*/true);

  // The band's events in the segment's frame: u along it from its centre, v across it.
  u_.clear();
  v_.clear();
  const float band = kBandRatio * b;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const Point2 d = Point2(points_.x()[i], points_.y()[i]) - centre;
    const float u = d.dot(unit), v = d.dot(normal);
    if (std::abs(v) > band || std::abs(u) > half_span) continue;
    u_.push_back(u);
    v_.push_back(v);
  }
  if (u_.size() < 6 || runs_on_straight(length)) return false;

  // v = a + t u + c u^2 with u scaled to [-1, 1] over the span, by robustly reweighted least squares:
  // c is how far the middle of the fitted curve lies off the chord between its ends.
  Eigen::Vector3d curve = Eigen::Vector3d::Zero();
  for (int round = 0; round <= kReweights; ++round) {
    Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < u_.size(); ++i) {
      const double u = u_[i] / half_span, v = v_[i];
      const Eigen::Vector3d basis(1.0, u, u * u);
      const double w = round == 0 ? 1.0 : 1.0 / (1.0 + std::abs(v - curve.dot(basis)) / kFairScale);
      normal_matrix.noalias() += w * basis * basis.transpose();
      rhs.noalias() += w * v * basis;
    }
    const Eigen::LDLT<Eigen::Matrix3d> solver(normal_matrix);
    if (solver.info() != Eigen::Success) return false;
    curve = solver.solve(rhs);
  }
  const double tilt = std::abs(curve[1]), bend = std::abs(curve[2]);
  if (bend < min_bend_px_ || tilt > kMaxTilt * bend) return false;
  return followed_beyond_both_ends(curve, length, half_span);
}

}  // namespace evldt
