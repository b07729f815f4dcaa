#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "evldt/lines/line_map.hpp"
#include "evldt/lines/normal_motion.hpp"

namespace evldt {
namespace {

Segment horizontal_at(float y) { return {Point2(10, y), Point2(40, y)}; }

TEST(NormalMotion, ALineDrawnLeftToRightMovingDownHasAPositiveVelocity) {
  EXPECT_TRUE(unit_normal(horizontal_at(5)).isApprox(Point2(0, 1)));
  const MotionParams params;
  NormalMotion motion;
  start_motion(motion, horizontal_at(20), 0, params);
  EXPECT_FLOAT_EQ(motion.velocity, 0.0f);
  EXPECT_FLOAT_EQ(motion.velocity_std(), params.initial_velocity_std);
  // 300 px/s down, a round every 2 ms, its band's middle within +-0.5 px of the edge.
  std::mt19937 random(3);
  std::uniform_real_distribution<float> jitter(-0.5f, 0.5f);
  for (int k = 1; k <= 100; ++k) {
    const float y = 20 + 0.6f * static_cast<float>(k);
    const Segment line = horizontal_at(y);
    observe_motion(motion, line, line.centre() + Point2(0, jitter(random)), 2000 * k, params);
  }
  // Within its own deviation, which is a fraction of the speed.
  EXPECT_NEAR(motion.velocity, 300.0f, 2.5f * motion.velocity_std());
  EXPECT_LT(motion.velocity_std(), 0.25f * 300.0f);
  // The same edge drawn the other way round moves against its own normal.
  const float before = motion.velocity;
  const Segment reversed{Point2(40, 80.6f), Point2(10, 80.6f)};
  observe_motion(motion, reversed, reversed.centre(), 202'000, params);
  EXPECT_LT(motion.velocity, 0.0f);
  EXPECT_NEAR(motion.velocity, -before, 0.1f * before);
}

TEST(NormalMotion, AStillLineSettlesAtZeroAndAPointIsNoObservation) {
  const MotionParams params;
  NormalMotion motion;
  observe_motion(motion, {Point2(3, 3), Point2(3, 3)}, Point2(3, 3), 0, params);
  EXPECT_FALSE(motion.started);
  for (int k = 0; k < 200; ++k) observe_motion(motion, horizontal_at(20), horizontal_at(20).centre(), 2000 * k, params);
  EXPECT_NEAR(motion.velocity, 0.0f, 1e-3f);
  EXPECT_LT(motion.velocity_std(), 30.0f);
}

// The line map: a re-detected line takes over the motion of the line released there, and a new
// piece of an edge the motion of the live line it continues.
TEST(LineMapMotion, ANewLineTakesTheVelocityOfTheEdgeItContinues) {
  const LatticeGeometry geometry = LatticeGeometry::make(SensorSize{64, 64}, 8, 1.0);
  LineMap lines(geometry);
  const int block = geometry.block_at(20, 20), right = geometry.block_at(28, 20);
  lines.add({Point2(16, 20), Point2(24, 20)}, 0.5f, block, 0);
  // Tracked down at 200 px/s for 40 ms.
  for (int k = 1; k <= 20; ++k) {
    TrackedLine& line = lines.lines()[0];
    line.status = LineStatus::GoodTrack;
    const float y = 20 + 0.4f * static_cast<float>(k);
    line.segment = {Point2(16, y), Point2(24, y)};
    lines.band_centre(0) = line.segment.centre();
    lines.observe_motion(2000 * k);
  }
  EXPECT_NEAR(lines.lines()[0].normal_velocity, 200.0f, 20.0f);
  // A piece of the same edge in the next block, drawn the other way round: the same motion, negated.
  lines.add({Point2(32, 28), Point2(24, 28)}, 0.5f, right, 40'000);
  EXPECT_NEAR(lines.lines()[1].normal_velocity, -lines.lines()[0].normal_velocity, 1e-3f);
  // Released and detected again along where it was: its id and its velocity.
  const std::uint64_t id = lines.lines()[0].id;
  const float velocity = lines.lines()[0].normal_velocity;
  lines.release(0, ReleaseReason::BadTracks);
  lines.release(0, ReleaseReason::BadTracks);
  EXPECT_EQ(lines.add({Point2(16, 28.5f), Point2(24, 28.5f)}, 0.5f, block, 50'000), id);
  EXPECT_FLOAT_EQ(lines.lines()[0].normal_velocity, velocity);
  // Nothing along it: no velocity known.
  lines.add({Point2(48, 40), Point2(48, 48)}, 0.5f, geometry.block_at(48, 44), 50'000);
  EXPECT_FLOAT_EQ(lines.lines()[1].normal_velocity, 0.0f);
}

}  // namespace
}  // namespace evldt
