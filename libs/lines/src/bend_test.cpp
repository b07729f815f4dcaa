#include "evldt/lines/bend_test.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <Eigen/Dense>

#include "evldt/lines/tracker.hpp"

namespace evldt {

namespace {
constexpr float kBandRatio = 0.4f;  // of b: events this far across the segment are fitted
constexpr float kFairScale = 1.0f;  // px: robust weight 1 / (1 + |residual| / scale)
constexpr int kReweights = 3;
constexpr float kMinBendPx = 2.0f;    // px: pixel noise alone bends a fit over three blocks of 8-10 px this much
constexpr float kMaxTilt = 0.7f;      // |linear| / |quadratic| above this: one end lifted alone, a corner
constexpr float kOnStraight = 0.3f;   // px: an event this close to the segment's line continues it
constexpr float kMinStraight = 0.6f;  // share of an end's far bins holding such an event: it runs on straight
constexpr float kOnCurve = 1.5f;      // px: an event this close to the fitted curve follows it
constexpr float kMinOnCurve = 0.6f;   // share of each end's bins that must hold such an event
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
  after_.reserve(most_points);
  entry_along_.resize(static_cast<std::size_t>(geometry.capacity));
  entry_offsets_.resize(static_cast<std::size_t>(geometry.capacity));
  entry_keys_.resize(static_cast<std::size_t>(geometry.capacity));
}

bool BendTest::runs_straight(const ScarfLattice& lattice, const Frame& frame, Point2 end, Point2 outward,
                             std::vector<float>& offsets) {
  // The far half of the extension, [b/2, b) beyond the end, in 1-px bins. The block whose region
  // is centred nearest the middle of that stretch holds its whole band: the middle lies within b/2
  // of the region's centre each way, the band's rectangle (b/2 long, 0.8 b wide) within 0.47 b of
  // its middle, and a region reaches b from its centre. Its ring holds the newest events there, each
  // once (the rings of the blocks the stretch crosses hold most of them two to four times).
  const int b = geometry_.block_size, near = b / 2, far = b - near;
  const float band = kBandRatio * static_cast<float>(b);
  const float half_length = 0.5f * frame.length;
  const float cx = frame.centre.x(), cy = frame.centre.y(), nx = frame.normal.x(), ny = frame.normal.y();
  const float ox = outward.x(), oy = outward.y();
  const Point2 middle = end + (0.75f * static_cast<float>(b)) * outward;
  const int cell =
      geometry_.index(nearest_region(middle.x(), geometry_.blocks_x), nearest_region(middle.y(), geometry_.blocks_y));
  // Whether an entry lies in the band there is data (about one in six does): branches on it
  // mispredict. A first loop the compiler vectorises works out each entry's offset and its key:
  // its bin when on the segment's line, kInBand when only in the band, kOutside. A second marks
  // the bins (bits 0..far-1 of marks, far <= 32) and compacts the offsets without a branch.
  constexpr std::int32_t kInBand = 32, kOutside = 33;
  float* entry_offsets = entry_offsets_.data();
  std::int32_t* entry_keys = entry_keys_.data();
  std::uint64_t marks = 0;
  std::size_t n = 0;
  offsets.clear();
  {
    const BlockEntries block = lattice.entries(cell);
    const std::size_t count = block.entries.size();
    const LatticeEntry* entries = block.entries.data();
    for (std::size_t i = 0; i < count; ++i) {
      // As Point2 arithmetic would round them: the centre's offset, then each product and sum.
      const float dx = (static_cast<float>(block.pixel_x(entries[i])) + 0.5f) - cx;
      const float dy = (static_cast<float>(block.pixel_y(entries[i])) + 0.5f) - cy;
      const float v = dx * nx + dy * ny;
      const float beyond = (dx * ox + dy * oy) - half_length;
      const bool inside =
          (std::abs(v) <= band) & (beyond >= static_cast<float>(near)) & (beyond < static_cast<float>(b));
      const std::int32_t bin = static_cast<std::int32_t>(beyond) - near;
      entry_offsets[i] = v;
      entry_keys[i] = !inside ? kOutside : std::abs(v) <= kOnStraight ? bin : kInBand;
    }
    offsets.resize(n + count);
    for (std::size_t i = 0; i < count; ++i) {
      offsets[n] = entry_offsets[i];
      n += entry_keys[i] != kOutside;
      marks |= std::uint64_t{1} << entry_keys[i];
    }
  }
  offsets.resize(n);
  const auto on_line = static_cast<std::uint32_t>(marks);  // the bins alone
  return static_cast<float>(std::popcount(on_line)) >= kMinStraight * static_cast<float>(far);
}

int BendTest::nearest_region(float coordinate, int blocks) const {
  // Block k's region spans [k b, (k + 2) b): its centre is (k + 1) b.
  const float k = std::round(coordinate / static_cast<float>(geometry_.block_size)) - 1.0f;
  return static_cast<int>(std::clamp(k, 0.0f, static_cast<float>(blocks - 1)));
}

int BendTest::median_sign(const std::vector<float>& offsets) {
  // The median is element n / 2 in sorted order: negative when more than n / 2 offsets are, positive
  // when at most n / 2 are not. Two counts, no sort.
  const std::size_t n = offsets.size(), middle = n / 2;
  if (n == 0) return 0;
  std::size_t negative = 0, positive = 0;
  for (const float v : offsets) {
    negative += v < 0;
    positive += v > 0;
  }
  return middle < negative ? -1 : middle >= n - positive ? 1 : 0;
}

float BendTest::median(std::vector<float>& offsets) {
  if (offsets.empty()) return 0.0f;
  const auto middle = offsets.begin() + static_cast<std::ptrdiff_t>(offsets.size() / 2);
  std::nth_element(offsets.begin(), middle, offsets.end());
  return *middle;
}

bool BendTest::followed_beyond_both_ends(const Eigen::Vector3d& curve, float length, float half_span) {
  // Per end, bit i: the bin [i, i + 1) px beyond it holds an event on the curve (b <= 64 bins).
  const int b = geometry_.block_size;
  std::uint64_t followed[2] = {0, 0};  // beyond q0, beyond q1
  for (std::size_t i = 0; i < u_.size(); ++i) {
    const double u = u_[i] / half_span;
    if (std::abs(v_[i] - (curve[0] + curve[1] * u + curve[2] * u * u)) > kOnCurve) continue;
    const float beyond = std::abs(u_[i]) - 0.5f * length;
    if (beyond < 0 || beyond >= static_cast<float>(b)) continue;
    followed[u_[i] > 0] |= std::uint64_t{1} << static_cast<int>(beyond);
  }
  for (const std::uint64_t bins : followed) {
    if (static_cast<float>(std::popcount(bins)) < kMinOnCurve * static_cast<float>(b)) return false;
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
  if (runs_straight(lattice, frame, segment.q0, -unit, v_) || runs_straight(lattice, frame, segment.q1, unit, after_)) {
    return false;
  }
  // An arc lies off to the same side beyond both ends (the median offsets); a cheap look that spares
  // most fits. Mostly decided by the medians' signs; their product also when it can underflow.
  if (median_sign(v_) * median_sign(after_) <= 0 || median(v_) * median(after_) <= 0) return false;

  const float half_span = 0.5f * length + b;
  cells_.clear();
  blocks_along({segment.q0 - b * unit, segment.q1 + b * unit}, geometry_, cells_);
  // The band's events (all entries of the blocks along it, active or not) in the segment's frame: u
  // along it from its centre, v across it.
  // Two loops as in runs_straight; the compaction keeps the order, on which the fit's sums depend.
  const float band = kBandRatio * b;
  const float cx = centre.x(), cy = centre.y(), ux = unit.x(), uy = unit.y(), nx = normal.x(), ny = normal.y();
  float* entry_along = entry_along_.data();
  float* entry_offsets = entry_offsets_.data();
  std::int32_t* entry_keys = entry_keys_.data();
  std::size_t n = 0;
  for (const int cell : cells_) {
    const BlockEntries block = lattice.entries(cell);
    const std::size_t count = block.entries.size();
    const LatticeEntry* entries = block.entries.data();
    for (std::size_t i = 0; i < count; ++i) {
      const float dx = (static_cast<float>(block.pixel_x(entries[i])) + 0.5f) - cx;
      const float dy = (static_cast<float>(block.pixel_y(entries[i])) + 0.5f) - cy;
      const float u = dx * ux + dy * uy, v = dx * nx + dy * ny;
      entry_along[i] = u;
      entry_offsets[i] = v;
      entry_keys[i] =
          static_cast<std::int32_t>(std::abs(v) <= band) & static_cast<std::int32_t>(std::abs(u) <= half_span);
    }
    u_.resize(n + count);
    v_.resize(n + count);
    for (std::size_t i = 0; i < count; ++i) {
      u_[n] = entry_along[i];
      v_[n] = entry_offsets[i];
      n += static_cast<std::size_t>(entry_keys[i]);
    }
  }
  u_.resize(n);
  v_.resize(n);
  if (n < 6) return false;

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
