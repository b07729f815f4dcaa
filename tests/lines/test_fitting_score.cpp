#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "evldt/lines/fitting_score.hpp"
#include "evldt/lines/line_fit.hpp"

namespace evldt {
namespace {

// Entries of a block whose extended region begins at the origin, so an entry's place is its pixel.
LatticeEntry entry(int x, int y, bool active = true) { return LatticeEntry::make(x, y, active); }

PointSet point_set(const std::vector<LatticeEntry>& entries, bool include_inactive) {
  PointSet points;
  points.add(BlockEntries{entries, 0, 0}, include_inactive);
  return points;
}

// Segment along y = 4.5 from x = 4 to 12 (|L| = 8); b = 8 so d_max = 1.6; N = 32.
class FittingScoreTest : public ::testing::Test {
 protected:
  FittingScorer scorer{1.6f, 100.0f};
  Segment segment{Point2(4.0f, 4.5f), Point2(12.0f, 4.5f)};
};

TEST_F(FittingScoreTest, FullRowOfInliers) {
  std::vector<LatticeEntry> points;
  for (int x = 4; x < 12; ++x) points.push_back(entry(x, 4));  // centres 4.5..11.5: bins 0..7
  const auto s = scorer.score(segment, point_set(points, false), 32.0f);
  EXPECT_FLOAT_EQ(s.occupancy, 1.0f);
  EXPECT_EQ(s.inliers, 8);
  EXPECT_FLOAT_EQ(s.effective, 0.25f);
  EXPECT_FLOAT_EQ(s.score(), 0.25f);
}

TEST_F(FittingScoreTest, HalfOccupancyAndOutliersIgnored) {
  std::vector<LatticeEntry> points;
  for (int x = 4; x < 8; ++x) points.push_back(entry(x, 4));  // bins 0..3 -> r_o = 4/8
  points.push_back(entry(5, 4));                              // duplicate pixel: one more active inlier, same bin
  points.push_back(entry(9, 6));                              // 2 px off the line (d1 = 2 >= 1.6): outlier
  points.push_back(entry(12, 4));                             // centre at d2 = 8.5 > |L|: beyond the end
  points.push_back(entry(3, 4));                              // d2 = -0.5 < 0: before the start
  const auto s = scorer.score(segment, point_set(points, false), 32.0f);
  EXPECT_FLOAT_EQ(s.occupancy, 0.5f);
  EXPECT_EQ(s.inliers, 5);
  EXPECT_FLOAT_EQ(s.score(), 0.5f * 5.0f / 32.0f);
}

TEST_F(FittingScoreTest, InactiveEntriesArePointsOnlyWhenAllowed) {
  std::vector<LatticeEntry> points;
  for (int x = 4; x < 8; ++x) points.push_back(entry(x, 4));
  for (int x = 8; x < 12; ++x) points.push_back(entry(x, 5, /*active=*/false));  // d1 = 1 < 1.6
  const auto without = scorer.score(segment, point_set(points, false), 32.0f);
  EXPECT_FLOAT_EQ(without.occupancy, 0.5f);
  EXPECT_EQ(without.inliers, 4);
  const auto with = scorer.score(segment, point_set(points, true), 32.0f);
  EXPECT_FLOAT_EQ(with.occupancy, 1.0f);
  EXPECT_EQ(with.inliers, 8);
  EXPECT_FLOAT_EQ(with.score(), 8.0f / 32.0f);
  EXPECT_FLOAT_EQ(with.mean_inlier_distance(), 0.5f);  // d1 = 0 for y = 4, 1 for y = 5
  // The normaliser divides r_e (k*N for a union of k blocks).
  EXPECT_FLOAT_EQ(scorer.score(segment, point_set(points, true), 64.0f).score(), 4.0f / 32.0f);
}

TEST_F(FittingScoreTest, OccupancyIsCappedAtOneAndDegenerateSegmentsScoreZero) {
  std::vector<LatticeEntry> points;
  for (int x = 0; x < 20; ++x) points.push_back(entry(x, 4));
  const Segment short_one{Point2(4.0f, 4.5f), Point2(6.5f, 4.5f)};  // |L| = 2.5, bins 0..2: 3/2.5 -> 1
  EXPECT_FLOAT_EQ(scorer.score(short_one, point_set(points, false), 32.0f).occupancy, 1.0f);
  const Segment point_like{Point2(4.0f, 4.5f), Point2(4.0f, 4.5f)};
  EXPECT_FLOAT_EQ(scorer.score(point_like, point_set(points, false), 32.0f).score(), 0.0f);
}

TEST(LineFit, RobustWeightsResistAnOutlier) {
  std::vector<LatticeEntry> points;
  for (int x = 0; x < 12; ++x) points.push_back(entry(x, 10));
  points.push_back(entry(6, 16));
  points.push_back(entry(6, 17, /*active=*/false));  // inactive entries are not gathered for a fit
  const auto plain = fit_line(point_set(points, false), 0);
  const auto robust = fit_line(point_set(points, false), 5);
  ASSERT_TRUE(plain && robust);
  const float plain_tilt = std::abs(plain->direction.y() / plain->direction.x());
  const float robust_tilt = std::abs(robust->direction.y() / robust->direction.x());
  EXPECT_LT(robust_tilt, plain_tilt);
  EXPECT_NEAR(robust->point.y(), 10.5f, 0.25f);
  EXPECT_LT(std::abs(plain->point.y() - 10.5f), 0.6f);
}

TEST(LineFit, NeedsTwoDistinctPixels) {
  std::vector<LatticeEntry> same(5, entry(3, 3));
  EXPECT_FALSE(fit_line(point_set(same, false), 3));
  EXPECT_FALSE(fit_line(PointSet{}, 3));
}

TEST(ClipToSquare, EndpointsLieOnTheBlockBorder) {
  const auto diagonal = clip_to_square({Point2(8, 8), Point2(1, 1).normalized()}, 4, 4, 8);
  ASSERT_TRUE(diagonal);
  EXPECT_FLOAT_EQ(diagonal->q0.x(), 4.0f);
  EXPECT_FLOAT_EQ(diagonal->q0.y(), 4.0f);
  EXPECT_FLOAT_EQ(diagonal->q1.x(), 12.0f);
  EXPECT_FLOAT_EQ(diagonal->q1.y(), 12.0f);
  const auto steep = clip_to_square({Point2(7.3f, 9.0f), Point2(0.2f, 1.0f).normalized()}, 4, 4, 8);
  ASSERT_TRUE(steep);
  EXPECT_FLOAT_EQ(steep->q0.y(), 4.0f);
  EXPECT_FLOAT_EQ(steep->q1.y(), 12.0f);
  EXPECT_NEAR(steep->q1.x() - steep->q0.x(), 1.6f, 1e-4f);
  EXPECT_FALSE(clip_to_square({Point2(20, 20), Point2(1, 0)}, 4, 4, 8));
}

}  // namespace
}  // namespace evldt
