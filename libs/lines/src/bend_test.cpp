#include "evldt/lines/bend_test.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Dense>

#include "evldt/lines/tracker.hpp"

namespace evldt {

namespace {
constexpr float kBandRatio = 0.4f;     // of b: events this far across the segment are fitted
constexpr float kFairScale = 1.0f;     // px: robust weight 1 / (1 + |residual| / scale)
constexpr int kReweights = 3;
constexpr float kMinBendPx = 2.0f;     // px: pixel noise alone bends a fit over three blocks of 8-10 px this much
constexpr float kMaxTilt = 0.7f;       // |linear| / |quadratic| above this: one end lifted alone, a corner
constexpr float kOnStraight = 0.3f;    // px: an event this close to the segment's line continues it
constexpr float kMinStraight = 0.6f;   // share of an end's far bins holding such an event: it runs on straight
constexpr float kOnCurve = 1.5f;       // px: an event this close to the fitted curve follows it
constexpr float kMinOnCurve = 0.6f;    // share of each end's bins that must hold such an event

Point2 pixel_centre(const BlockEntries& block, LatticeEntry entry) {
  return {static_cast<float>(block.pixel_x(entry)) + 0.5f, static_cast<float>(block.pixel_y(entry)) + 0.5f};
}
}  // namespace

BendTest::BendTest(const LatticeGeometry& geometry, float max_bend_ratio)
    : geometry_(geometry),
      min_bend_px_(max_bend_ratio > 0 ? std::max(max_bend_ratio * static_cast<float>(geometry.block_size), kMinBendPx)
                                      : 0.0f) {
  // A segment within one block, extended by b at each end, crosses at most 8 blocks (3 b each way
  // and the corners between).
  constexpr std::size_t kLongestWalk = 8;
  const auto most_points = kLongestWalk * static_cast<std::size_t>(geometry.capacity);
  cells_.reserve(kLongestWalk);
  u_.reserve(most_points);
  v_.reserve(most_points);
  bins_.resize(static_cast<std::size_t>(2 * geometry.block_size));
}

std::optional<float> BendTest::far_offset(const ScarfLattice& lattice, const Frame& frame, Point2 end, Point2 outward) {
  // The far half of the extension, [b/2, b) beyond the end, in 1-px bins. Its blocks hold every
  // event of the band there (a block's region reaches b/2 beyond its square, the band 0.4 b).
  const int b = geometry_.block_size, near = b / 2, far = b - near;
  const float band = kBandRatio * static_cast<float>(b);
  cells_.clear();
  blocks_along({end + static_cast<float>(near) * outward, end + static_cast<float>(b) * outward}, geometry_, cells_);
  std::fill(bins_.begin(), bins_.begin() + far, 0);
  v_.clear();
  for (const int cell : cells_) {
    const BlockEntries block = lattice.entries(cell);
    for (const LatticeEntry entry : block.entries) {
      const Point2 d = pixel_centre(block, entry) - frame.centre;
      const float v = d.dot(frame.normal);
      const float beyond = d.dot(outward) - 0.5f * frame.length;
      if (std::abs(v) > band || beyond < static_cast<float>(near) || beyond >= static_cast<float>(b)) continue;
      v_.push_back(v);
      if (std::abs(v) <= kOnStraight) bins_[static_cast<std::size_t>(static_cast<int>(beyond) - near)] = 1;
    }
  }
  if (static_cast<float>(std::count(bins_.begin(), bins_.begin() + far, 1)) >= kMinStraight * static_cast<float>(far)) {
    return std::nullopt;
  }
  if (v_.empty()) return 0.0f;
  const auto middle = v_.begin() + static_cast<std::ptrdiff_t>(v_.size() / 2);
  std::nth_element(v_.begin(), middle, v_.end());
  return *middle;
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
  // The common case, a straight edge, is decided from the few blocks beyond one end.
  const Frame frame{centre, normal, length};
  const auto before = far_offset(lattice, frame, segment.q0, -unit);
  if (!before) return false;
  const auto after = far_offset(lattice, frame, segment.q1, unit);
  // An arc lies off to the same side beyond both ends; a cheap look that spares most fits.
  if (!after || *before * *after <= 0) return false;

  const float half_span = 0.5f * length + b;
  cells_.clear();
  blocks_along({segment.q0 - b * unit, segment.q1 + b * unit}, geometry_, cells_);
  // The band's events (all entries of the blocks along it, active or not) in the segment's frame: u
  // along it from its centre, v across it.
  u_.clear();
  v_.clear();
  const float band = kBandRatio * b;
  for (const int cell : cells_) {
    const BlockEntries block = lattice.entries(cell);
    for (const LatticeEntry entry : block.entries) {
      const Point2 d = pixel_centre(block, entry) - centre;
      const float u = d.dot(unit), v = d.dot(normal);
      if (std::abs(v) > band || std::abs(u) > half_span) continue;
      u_.push_back(u);
      v_.push_back(v);
    }
  }
  if (u_.size() < 6) return false;

  // v = a + t u + c u^2 with u scaled to [-1, 1] over the span, by robustly reweighted least squares:
  // c is how far the middle of the fitted curve lies off the chord between its ends. The weighted
  // sums (some hundred terms, each at most b) in float, the 3x3 system in double.
  Eigen::Vector3d curve = Eigen::Vector3d::Zero();
  const float inverse_span = 1.0f / half_span;
  for (int round = 0; round <= kReweights; ++round) {
    const auto a = static_cast<float>(curve[0]), t = static_cast<float>(curve[1]), c = static_cast<float>(curve[2]);
    float s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, r0 = 0, r1 = 0, r2 = 0;
    for (std::size_t i = 0; i < u_.size(); ++i) {
      const float u = u_[i] * inverse_span, v = v_[i], uu = u * u;
      const float w = round == 0 ? 1.0f : 1.0f / (1.0f + std::abs(v - (a + t * u + c * uu)) * (1.0f / kFairScale));
      const float wu = w * u, wuu = w * uu;
      s0 += w;
      s1 += wu;
      s2 += wuu;
      s3 += wuu * u;
      s4 += wuu * uu;
      r0 += w * v;
      r1 += wu * v;
      r2 += wuu * v;
    }
    Eigen::Matrix3d normal_matrix;
    normal_matrix << s0, s1, s2, s1, s2, s3, s2, s3, s4;
    const Eigen::LDLT<Eigen::Matrix3d> solver(normal_matrix);
    if (solver.info() != Eigen::Success) return false;
    curve = solver.solve(Eigen::Vector3d(r0, r1, r2));
  }
  const double tilt = std::abs(curve[1]), bend = std::abs(curve[2]);
  if (bend < min_bend_px_ || tilt > kMaxTilt * bend) return false;
  return followed_beyond_both_ends(curve, length, half_span);
}

}  // namespace evldt
