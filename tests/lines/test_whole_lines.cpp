#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "evldt/lines/whole_lines.hpp"

namespace evldt {
namespace {

constexpr int kBlock = 8;  // default joins: 12 degrees, ends within 4.8 px, gaps up to 16 px

TrackedLine segment(std::uint64_t id, float x0, float y0, float x1, float y1) {
  return {.id = id, .segment = {Point2(x0, y0), Point2(x1, y1)}, .status = LineStatus::GoodTrack};
}

/// Block segments along y = 20 + dy from x = 4 to 36 (ids 1-4), and a parallel edge 10 px below (id 9).
std::vector<TrackedLine> edge_pieces(float dy = 0) {
  return {segment(1, 4, 20 + dy, 12, 20 + dy), segment(2, 12, 20 + dy, 20, 20.5f + dy),
          segment(3, 20, 20.5f + dy, 28, 20 + dy), segment(4, 28, 20 + dy, 36, 20 + dy),
          segment(9, 4, 30 + dy, 12, 30 + dy)};
}

const WholeLine& line_holding(const WholeLineTracker& tracker, float y) {
  for (const WholeLine& l : tracker.lines()) {
    if (std::abs(l.segment.centre().y() - y) < 2) return l;
  }
  throw std::logic_error("no line there");
}

TEST(WholeLineTracker, JoinsTouchingCollinearSegmentsAndKeepsAParallelEdgeApart) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, edge_pieces());
  ASSERT_EQ(tracker.lines().size(), 2u);
  const WholeLine& joined = line_holding(tracker, 20.1f);
  EXPECT_EQ(joined.segments, 4u);
  EXPECT_NEAR(std::min(joined.segment.q0.x(), joined.segment.q1.x()), 4.0f, 0.1f);
  EXPECT_NEAR(std::max(joined.segment.q0.x(), joined.segment.q1.x()), 36.0f, 0.1f);
  EXPECT_EQ(line_holding(tracker, 30).segments, 1u);
}

TEST(WholeLineTracker, ALineKeepsItsIdWhileItsSegmentsChange) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, edge_pieces());
  const std::uint64_t id = line_holding(tracker, 20.1f).id;
  // The edge moves down 1 px, segment 1 is lost and a new one (id 7) continues the edge to the right.
  std::vector<TrackedLine> next = edge_pieces(1);
  next.erase(next.begin());
  next.push_back(segment(7, 36, 21, 44, 21));
  tracker.update(10, next);
  const WholeLine& moved = line_holding(tracker, 21.1f);
  EXPECT_EQ(moved.id, id);
  EXPECT_EQ(moved.first_seen_us, 0);
  EXPECT_EQ(moved.last_seen_us, 10);
  EXPECT_EQ(moved.segments, 4u);
  EXPECT_EQ(tracker.created(), 2u);
}

TEST(WholeLineTracker, OfASplitLineTheLongerPartKeepsTheId) {
  WholeLineTracker tracker(kBlock);
  const std::vector<TrackedLine> whole = {segment(1, 4, 20, 12, 20), segment(2, 12, 20, 20, 20),
                                          segment(3, 20, 20, 28, 20), segment(4, 28, 20, 36, 20),
                                          segment(5, 36, 20, 44, 20)};
  tracker.update(0, whole);
  ASSERT_EQ(tracker.lines().size(), 1u);
  const std::uint64_t id = tracker.lines()[0].id;
  // The middle piece turns away (an occluder's edge) and the right part now starts 24 px on, more
  // than the 16 px gap a line may bridge; the left part (20 px) is longer than the right (16 px).
  const std::vector<TrackedLine> split = {segment(1, 0, 20, 12, 20), whole[1], segment(3, 20, 20, 26, 28),
                                          segment(4, 44, 20, 52, 20), segment(5, 52, 20, 60, 20)};
  tracker.update(10, split);
  EXPECT_EQ(line_holding(tracker, 20).id, id);
  std::size_t with_old_id = 0;
  for (const WholeLine& l : tracker.lines()) with_old_id += l.id == id ? 1 : 0;
  EXPECT_EQ(with_old_id, 1u);
  EXPECT_EQ(tracker.lines().size(), 3u);
  for (const WholeLine& l : tracker.lines()) {
    if (l.id == id) EXPECT_LT(l.segment.centre().x(), 20.0f);
  }
}

TEST(WholeLineTracker, ALineLostForAMomentComesBackUnderItsIdButNotAfterKeepId) {
  WholeLineTracker tracker(kBlock);
  const std::vector<TrackedLine> edge = {segment(1, 4, 20, 12, 20), segment(2, 12, 20, 20, 20)};
  tracker.update(0, edge);
  const std::uint64_t id = tracker.lines()[0].id;
  tracker.update(50'000, {});
  // New segment ids along the same stretch: taken up by geometry within keep_id_us.
  tracker.update(100'000, std::vector<TrackedLine>{segment(11, 5, 21, 13, 21), segment(12, 13, 21, 21, 21)});
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, id);
  EXPECT_EQ(tracker.lines()[0].first_seen_us, 0);
  tracker.update(150'000, {});
  tracker.update(200'001, std::vector<TrackedLine>{segment(21, 5, 21, 13, 21)});
  EXPECT_NE(tracker.lines()[0].id, id);
}

TEST(WholeLineTracker, SegmentsJoinedAtTheLastStepStayJoinedThroughAWobble) {
  // Ids 1 and 2 along y = 20; then id 2 wobbles by 15 degrees (beyond the 12 of a first join, within
  // twice that for segments that were one line).
  const std::vector<TrackedLine> straight = {segment(1, 4, 20, 20, 20), segment(2, 20, 20, 28, 20)};
  const std::vector<TrackedLine> wobbled = {segment(1, 4, 20, 20, 20), segment(2, 20, 20, 27.73f, 22.07f)};
  WholeLineTracker first_sight(kBlock);
  first_sight.update(0, wobbled);
  EXPECT_EQ(first_sight.lines().size(), 2u);
  WholeLineTracker tracker(kBlock);
  tracker.update(0, straight);
  ASSERT_EQ(tracker.lines().size(), 1u);
  const std::uint64_t id = tracker.lines()[0].id;
  tracker.update(10, wobbled);
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, id);
  EXPECT_EQ(tracker.lines()[0].segments, 2u);
}

TEST(WholeLineTracker, SegmentsAlongACircleDoNotChainIntoOneLine) {
  // 36 chords of a circle of radius 40: neighbours differ by 10 degrees, within the join angle, but
  // the fitted line of a growing chain soon leaves every further chord.
  std::vector<TrackedLine> chords;
  for (int k = 0; k < 36; ++k) {
    const float a0 = static_cast<float>(k) * std::numbers::pi_v<float> / 18, a1 = a0 + std::numbers::pi_v<float> / 18;
    chords.push_back(segment(static_cast<std::uint64_t>(k + 1), 60 + 40 * std::cos(a0), 60 + 40 * std::sin(a0),
                             60 + 40 * std::cos(a1), 60 + 40 * std::sin(a1)));
  }
  WholeLineTracker tracker(kBlock);
  tracker.update(0, chords);
  EXPECT_GE(tracker.lines().size(), 12u);
  for (const WholeLine& l : tracker.lines()) EXPECT_LE(l.segments, 3u);
}

TEST(WholeLineTracker, RejectsStepsOutOfOrderAndABadBlockSize) {
  WholeLineTracker tracker(kBlock);
  tracker.update(10, {});
  EXPECT_THROW(tracker.update(9, {}), std::invalid_argument);
  EXPECT_THROW(WholeLineTracker(0), std::invalid_argument);
}

}  // namespace
}  // namespace evldt
