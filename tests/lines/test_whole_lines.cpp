#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

#include "evldt/lines/whole_lines.hpp"

namespace evldt {
namespace {

constexpr int kBlock = 8;  // default joins: 20 degrees, ends within 4.8 px, gaps up to 16 px; published from 24 px

TrackedLine segment(std::uint64_t id, float x0, float y0, float x1, float y1) {
  return {.id = id, .segment = {Point2(x0, y0), Point2(x1, y1)}, .status = LineStatus::GoodTrack};
}

/// Block segments along y = 20 + dy from x = 4 to 36 (ids 1-4), and a parallel edge 10 px below
/// from x = 4 to 28 (ids 9-11).
std::vector<TrackedLine> edge_pieces(float dy = 0) {
  return {segment(1, 4, 20 + dy, 12, 20 + dy),     segment(2, 12, 20 + dy, 20, 20.5f + dy),
          segment(3, 20, 20.5f + dy, 28, 20 + dy), segment(4, 28, 20 + dy, 36, 20 + dy),
          segment(9, 4, 30 + dy, 12, 30 + dy),     segment(10, 12, 30 + dy, 20, 30 + dy),
          segment(11, 20, 30 + dy, 28, 30 + dy)};
}

/// Segments of 8 px along y = `y` from x0 to x1, ids from first_id.
std::vector<TrackedLine> pieces_along(float y, float x0, float x1, std::uint64_t first_id) {
  std::vector<TrackedLine> out;
  for (float x = x0; x + 8 <= x1 + 0.01f; x += 8) out.push_back(segment(first_id++, x, y, x + 8, y));
  return out;
}

std::vector<TrackedLine> operator+(std::vector<TrackedLine> a, const std::vector<TrackedLine>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

const WholeLine& line_holding(const WholeLineTracker& tracker, float y) {
  for (const WholeLine& l : tracker.lines()) {
    if (std::abs(l.segment.centre().y() - y) < 2) return l;
  }
  throw std::logic_error("no line there");
}

float min_x(const WholeLine& l) { return std::min(l.segment.q0.x(), l.segment.q1.x()); }
float max_x(const WholeLine& l) { return std::max(l.segment.q0.x(), l.segment.q1.x()); }

/// Default parameters but for the ends' reach along the events, for tests of corners and remembered
/// ends alone (the reach holds a pixel by an event within 1.5 px, so it draws an end out by a pixel
/// wherever the events run to it).
WholeLineParams without_event_reach() {
  WholeLineParams params;
  params.event_reach_ratio = 0;
  return params;
}

/// Parameters that publish every line, for tests of the joins alone.
WholeLineParams publish_all() {
  WholeLineParams params;
  params.min_length_ratio = 0;
  return params;
}

TEST(WholeLineTracker, JoinsTouchingCollinearSegmentsAndKeepsAParallelEdgeApart) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, edge_pieces());
  ASSERT_EQ(tracker.lines().size(), 2u);
  const WholeLine& joined = line_holding(tracker, 20.1f);
  EXPECT_EQ(joined.segments, 4u);
  EXPECT_NEAR(min_x(joined), 4.0f, 0.1f);
  EXPECT_NEAR(max_x(joined), 36.0f, 0.1f);
  EXPECT_EQ(line_holding(tracker, 30).segments, 3u);
}

TEST(WholeLineTracker, ShortLinesAreNotPublishedAndTakeNoId) {
  WholeLineTracker tracker(kBlock);
  // 16 px and 8 px: both under 3 b.
  tracker.update(0, pieces_along(20, 4, 20, 1) + pieces_along(60, 4, 12, 5));
  EXPECT_TRUE(tracker.lines().empty());
  EXPECT_EQ(tracker.created(), 0u);
  // The first grows to 24 px: published now, and then while it lasts, also shorter again.
  tracker.update(10, pieces_along(20, 4, 28, 1));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].first_seen_us, 0);  // its track began before it was published
  const std::uint64_t id = tracker.lines()[0].id;
  tracker.update(20, pieces_along(20, 4, 12, 1));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, id);
  EXPECT_EQ(tracker.created(), 1u);
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

TEST(WholeLineTracker, AnEndItsSegmentsFallShortOfStaysForEndMemory) {
  WholeLineParams params;
  params.end_memory_us = 50;
  WholeLineTracker tracker(kBlock, params);
  tracker.update(0, pieces_along(20, 4, 52, 1));  // 6 segments, 4..52
  // The segments at both ends of the edge drop out: the ends stay.
  tracker.update(10, pieces_along(20, 12, 44, 2));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_NEAR(min_x(tracker.lines()[0]), 4.0f, 0.1f);
  EXPECT_NEAR(max_x(tracker.lines()[0]), 52.0f, 0.1f);
  EXPECT_EQ(tracker.lines()[0].segments, 4u);
  tracker.update(50, pieces_along(20, 12, 44, 2));
  EXPECT_NEAR(min_x(tracker.lines()[0]), 4.0f, 0.1f);
  EXPECT_NEAR(max_x(tracker.lines()[0]), 52.0f, 0.1f);
  // Not reached for longer than end_memory_us: the ends follow the segments.
  tracker.update(61, pieces_along(20, 12, 44, 2));
  EXPECT_NEAR(min_x(tracker.lines()[0]), 12.0f, 0.1f);
  EXPECT_NEAR(max_x(tracker.lines()[0]), 44.0f, 0.1f);
}

TEST(WholeLineTracker, ARememberedEndDoesNotFollowALineThatTurned) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces_along(20, 4, 52, 1));
  // What is left turns by 20 degrees (within the twice-as-loose bounds of former members).
  const float c = std::cos(20.0f * std::numbers::pi_v<float> / 180),
              s = std::sin(20.0f * std::numbers::pi_v<float> / 180);
  std::vector<TrackedLine> turned;
  for (std::uint64_t k = 0; k < 3; ++k) {
    const float x0 = 4 + 8.0f * static_cast<float>(k) * c, y0 = 20 + 8.0f * static_cast<float>(k) * s;
    turned.push_back(segment(k + 1, x0, y0, x0 + 8 * c, y0 + 8 * s));
  }
  tracker.update(10, turned);
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_NEAR(tracker.lines()[0].segment.length(), 24.0f, 0.1f);
}

// A line takes its former segments back along its last geometry. Block segments along an edge at
// -11 degrees, from boxes-6dof (each block's segment level, the edge a staircase of them); at the
// next step the end block's segment tilts to -28 degrees and is the longest of them. Fitted to that
// one first, the line refused the rest of its edge (24 degrees apart), which became a new line with
// a new id; along its last geometry it keeps them all.
TEST(WholeLineTracker, ATiltedLongestSegmentDoesNotSteerALineOffItsEdge) {
  const auto edge = [](float y_end, float y_start) {
    return std::vector<TrackedLine>{segment(538, 12, y_start, 20, y_end), segment(392, 20, 41.1f, 28, 41.1f),
                                    segment(368, 28, 39.7f, 36, 39.7f),   segment(314, 36, 38.0f, 44, 38.8f),
                                    segment(308, 44, 36.5f, 52, 36.5f),   segment(282, 52, 34.9f, 60, 34.9f),
                                    segment(450, 60, 33.1f, 68, 33.1f)};
  };
  WholeLineTracker tracker(kBlock);
  tracker.update(0, edge(42.9f, 44.0f));
  ASSERT_EQ(tracker.lines().size(), 1u);
  const std::uint64_t id = tracker.lines()[0].id;
  tracker.update(10, edge(41.3f, 45.6f));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, id);
  EXPECT_GE(tracker.lines()[0].segments, 6u);
  EXPECT_LE(min_x(tracker.lines()[0]), 20.0f);
  EXPECT_GE(max_x(tracker.lines()[0]), 60.0f);
}

TEST(WholeLineTracker, OfASplitLineTheLongerPartKeepsTheId) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces_along(20, 4, 68, 1));  // ids 1-8
  ASSERT_EQ(tracker.lines().size(), 1u);
  const std::uint64_t id = tracker.lines()[0].id;
  // The middle turns away (an occluder's edge) and the right part now starts 40 px on, more than
  // even the 32 px gap a line's own segments may bridge; the left part (32 px) is longer than the
  // right (24 px).
  const std::vector<TrackedLine> split =
      pieces_along(20, 4, 36, 1) + std::vector{segment(5, 36, 20, 42, 28)} + pieces_along(20, 76, 100, 6);
  tracker.update(10, split);
  ASSERT_EQ(tracker.lines().size(), 2u);
  for (const WholeLine& l : tracker.lines()) {
    if (l.id == id) {
      EXPECT_NEAR(min_x(l), 4.0f, 0.1f);
    } else {
      EXPECT_NEAR(min_x(l), 76.0f, 0.1f);
    }
  }
  EXPECT_EQ(tracker.created(), 2u);
}

TEST(WholeLineTracker, OfTwoLinesThatGrowTogetherTheOneFirstPublishedKeepsItsId) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces_along(20, 4, 36, 1));
  const std::uint64_t first = tracker.lines()[0].id;
  // A second line further along the edge, 24 px beyond the first's end.
  tracker.update(10, pieces_along(20, 4, 36, 1) + pieces_along(20, 60, 92, 11));
  ASSERT_EQ(tracker.lines().size(), 2u);
  // The segments between appear: one line, under the first id.
  tracker.update(20, pieces_along(20, 4, 36, 1) + pieces_along(20, 44, 52, 21) + pieces_along(20, 60, 92, 11));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, first);
  EXPECT_NEAR(max_x(tracker.lines()[0]), 92.0f, 0.1f);
}

TEST(WholeLineTracker, APublishedLineKeepsItsIdWhenItMergesWithAnOlderUnpublishedOne) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces_along(20, 60, 76, 11));  // 16 px: tracked, not published
  EXPECT_TRUE(tracker.lines().empty());
  tracker.update(10, pieces_along(20, 60, 76, 11) + pieces_along(20, 4, 36, 1));
  ASSERT_EQ(tracker.lines().size(), 1u);
  const std::uint64_t published = tracker.lines()[0].id;
  tracker.update(20, pieces_along(20, 60, 76, 11) + pieces_along(20, 4, 36, 1) + pieces_along(20, 44, 52, 21));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, published);
  EXPECT_NEAR(max_x(tracker.lines()[0]), 76.0f, 0.1f);
  EXPECT_EQ(tracker.created(), 1u);
}

TEST(WholeLineTracker, ASecondLineAlongAPublishedOneIsNotPublished) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces_along(20, 4, 68, 1));
  // New segments 6 px off the line (beyond the 4.8 px a new segment may be off it, within twice
  // that), along its length: a line of their own, shadowed by the published one.
  tracker.update(10, pieces_along(20, 4, 68, 1) + pieces_along(26, 12, 44, 21));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.created(), 1u);
}

TEST(WholeLineTracker, LinesWhoseEndsFallShortOfACornerMeetThere) {
  WholeLineTracker tracker(kBlock);
  // An L: a horizontal edge y = 20 ending at x = 40 and a vertical edge x = 50 starting at y = 30;
  // the corner (50, 20) lies 10 px from each end (within 2 b).
  std::vector<TrackedLine> corner = pieces_along(20, 8, 40, 1);
  for (std::uint64_t k = 0; k < 4; ++k) {
    corner.push_back(segment(11 + k, 50, 30 + 8.0f * static_cast<float>(k), 50, 38 + 8.0f * static_cast<float>(k)));
  }
  // Far from both (a corner 20 px off the nearest end): left alone.
  for (std::uint64_t k = 0; k < 4; ++k) {
    corner.push_back(segment(21 + k, 100, 40 + 8.0f * static_cast<float>(k), 100, 48 + 8.0f * static_cast<float>(k)));
  }
  tracker.update(0, corner);
  ASSERT_EQ(tracker.lines().size(), 3u);
  const WholeLine& horizontal = line_holding(tracker, 20);
  EXPECT_NEAR(max_x(horizontal), 50.0f, 0.01f);
  EXPECT_NEAR(min_x(horizontal), 8.0f, 0.01f);
  for (const WholeLine& l : tracker.lines()) {
    if (std::abs(l.segment.centre().x() - 50) < 1) {
      EXPECT_NEAR(std::min(l.segment.q0.y(), l.segment.q1.y()), 20.0f, 0.01f);
    } else if (std::abs(l.segment.centre().x() - 100) < 1) {
      EXPECT_NEAR(std::min(l.segment.q0.y(), l.segment.q1.y()), 40.0f, 0.01f);
    }
  }
  // Nearly parallel lines make no corner: a line at 25 degrees to the horizontal one (too steep to
  // join it), its end 8 px on.
  const float c = std::cos(25.0f * std::numbers::pi_v<float> / 180),
              s = std::sin(25.0f * std::numbers::pi_v<float> / 180);
  std::vector<TrackedLine> lines = pieces_along(20, 8, 40, 1);
  for (std::uint64_t k = 0; k < 4; ++k) {
    const float x0 = 48 + 8.0f * static_cast<float>(k) * c, y0 = 20 + 8.0f * static_cast<float>(k) * s;
    lines.push_back(segment(11 + k, x0, y0, x0 + 8 * c, y0 + 8 * s));
  }
  WholeLineParams steep;
  steep.corner_min_angle_deg = 30;
  WholeLineTracker tracker_steep(kBlock, steep);
  tracker_steep.update(0, lines);
  ASSERT_EQ(tracker_steep.lines().size(), 2u);
  EXPECT_NEAR(max_x(line_holding(tracker_steep, 20)), 40.0f, 0.01f);
}

TEST(WholeLineTracker, ALineLostForAMomentComesBackUnderItsIdButNotAfterKeepId) {
  WholeLineParams params;
  params.keep_id_us = 100'000;
  WholeLineTracker tracker(kBlock, params);
  tracker.update(0, pieces_along(20, 4, 36, 1));
  const std::uint64_t id = tracker.lines()[0].id;
  tracker.update(50'000, {});
  EXPECT_TRUE(tracker.lines().empty());
  // New segment ids along the same stretch, 1 px off: taken up by geometry within keep_id_us.
  tracker.update(100'000, pieces_along(21, 5, 37, 11));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, id);
  EXPECT_EQ(tracker.lines()[0].first_seen_us, 0);
  tracker.update(150'000, {});
  tracker.update(200'001, pieces_along(21, 5, 37, 21));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_NE(tracker.lines()[0].id, id);
}

/// pieces_along, every segment moving across itself at `velocity` px/s (down the image for
/// positive: the pieces run left to right) and known to within `std`.
std::vector<TrackedLine> moving_pieces(float y, float x0, float x1, std::uint64_t first_id, float velocity,
                                       float std = 20) {
  std::vector<TrackedLine> pieces = pieces_along(y, x0, x1, first_id);
  for (TrackedLine& piece : pieces) {
    piece.normal_velocity = velocity;
    piece.normal_velocity_std = std;
  }
  return pieces;
}

// three-lines-fast: a bar's edge moves 9 px between two steps, as far as the loose bounds reach; its
// block segments are detected anew under new ids at every step.
TEST(WholeLineTracker, ALineFollowsItsEdgeWhereItsMotionTakesIt) {
  const auto run = [](float velocity) {
    WholeLineTracker tracker(kBlock);
    std::vector<std::uint64_t> ids;
    for (int k = 0; k < 5; ++k) {
      const float y = 20 + 10.0f * static_cast<float>(k);  // 1000 px/s, steps of 10 ms
      tracker.update(10'000 * k, moving_pieces(y, 4, 36, 100 * static_cast<std::uint64_t>(k + 1), velocity));
      if (tracker.lines().size() != 1) return std::vector<std::uint64_t>{};
      ids.push_back(tracker.lines()[0].id);
    }
    return ids;
  };
  const std::vector<std::uint64_t> moving = run(1000);
  ASSERT_EQ(moving.size(), 5u);
  EXPECT_EQ(std::count(moving.begin(), moving.end(), moving[0]), 5);
  // Without the motion the line waits where its edge was and a new line takes the edge.
  const std::vector<std::uint64_t> still = run(0);
  ASSERT_EQ(still.size(), 5u);
  EXPECT_NE(still.back(), still.front());
}

TEST(WholeLineTracker, ALinesVelocityIsItsSegmentsWeightedByHowWellEachIsKnown) {
  WholeLineTracker tracker(kBlock);
  // Two well-known pieces at 100 px/s, two poorly known ones at 300; the line runs right to left, so
  // its normal points up the image and its velocity is negative.
  std::vector<TrackedLine> pieces = moving_pieces(20, 4, 20, 1, 100, 10) + moving_pieces(20, 20, 36, 3, 300, 1000);
  for (TrackedLine& piece : pieces) std::swap(piece.segment.q0, piece.segment.q1);
  for (TrackedLine& piece : pieces) piece.normal_velocity = -piece.normal_velocity;
  tracker.update(0, pieces);
  ASSERT_EQ(tracker.lines().size(), 1u);
  const WholeLine& line = tracker.lines()[0];
  const float sign =
      line.segment.q1.x() > line.segment.q0.x() ? 1.0f : -1.0f;  // down the image for a line to the right
  EXPECT_NEAR(sign * line.normal_velocity, 100.0f, 1.0f);
  // About the deviation of the mean of the two good ones, widened by the disagreement.
  EXPECT_GT(line.normal_velocity_std, 10.0f / std::sqrt(2.0f));
  EXPECT_LT(line.normal_velocity_std, 20.0f);
}

// boxes-6dof (motion seed 18, 7.78 s): a line that had shrunk to one short segment waited; its old
// geometry, stretched by a waiting line's loose bounds, fitted a published line's edge and took it,
// and that line's id, from it.
TEST(WholeLineTracker, AWaitingLineDoesNotTakeUpAnotherPublishedLinesEdge) {
  WholeLineTracker tracker(kBlock);
  // A along y = 20 (x 4-36); B along y = 26 (x 60-92), 6 px off A's line and 24 px beyond its end:
  // outside the bounds of a join, within those a waiting line looks along.
  tracker.update(0, pieces_along(20, 4, 36, 1) + pieces_along(26, 60, 92, 11));
  ASSERT_EQ(tracker.lines().size(), 2u);
  const std::uint64_t b_id = line_holding(tracker, 26).id;
  tracker.update(10'000, pieces_along(26, 60, 92, 11));  // A's segments are gone: A waits
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, b_id);
  EXPECT_EQ(tracker.lines()[0].segments, 4u);
}

TEST(WholeLineTracker, AWaitingLineTakesUpOnlySegmentsWithinAJoinsGapOfIt) {
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces_along(20, 4, 36, 1));
  const std::uint64_t id = tracker.lines()[0].id;
  tracker.update(10'000, {});
  // 24 px beyond its old end, farther than a join reaches (16 px): another edge, a new line, too
  // short to be published.
  tracker.update(20'000, pieces_along(20, 60, 76, 11));
  EXPECT_TRUE(tracker.lines().empty());
  // 12 px beyond it: its edge, taken up under its id.
  tracker.update(30'000, pieces_along(20, 48, 64, 21));
  ASSERT_EQ(tracker.lines().size(), 1u);
  EXPECT_EQ(tracker.lines()[0].id, id);
}

TEST(WholeLineTracker, SegmentsJoinedAtTheLastStepStayJoinedThroughAWobble) {
  // Ids 1 and 2 along y = 20; then id 2 wobbles by 22 degrees (beyond the 20 of a first join, within
  // the 24 of segments that were one line).
  const std::vector<TrackedLine> straight = {segment(1, 4, 20, 20, 20), segment(2, 20, 20, 28, 20)};
  const std::vector<TrackedLine> wobbled = {segment(1, 4, 20, 20, 20), segment(2, 20, 20, 27.42f, 23.0f)};
  WholeLineTracker first_sight(kBlock, publish_all());
  first_sight.update(0, wobbled);
  EXPECT_EQ(first_sight.lines().size(), 2u);
  WholeLineTracker tracker(kBlock, publish_all());
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
  // the fitted line of a growing chain soon leaves every further chord (after 40 degrees of arc at
  // most: 4 chords).
  std::vector<TrackedLine> chords;
  for (int k = 0; k < 36; ++k) {
    const float a0 = static_cast<float>(k) * std::numbers::pi_v<float> / 18, a1 = a0 + std::numbers::pi_v<float> / 18;
    chords.push_back(segment(static_cast<std::uint64_t>(k + 1), 60 + 40 * std::cos(a0), 60 + 40 * std::sin(a0),
                             60 + 40 * std::cos(a1), 60 + 40 * std::sin(a1)));
  }
  WholeLineParams params = publish_all();
  params.corner_reach_ratio = 0;  // neighbouring chords meet anyway
  WholeLineTracker tracker(kBlock, params);
  tracker.update(0, chords);
  EXPECT_GE(tracker.lines().size(), 9u);
  for (const WholeLine& l : tracker.lines()) EXPECT_LE(l.segments, 4u);
}

TEST(WholeLineTracker, ANewSegmentAcrossAGapJoinsOnlyWhereTheLatticeHoldsEventsAlongIt) {
  // Two edges on y = 20: x 8-40 and x 52-84, a 12 px gap between them (within the 16 px a gap may
  // span on geometry alone, over the 4 px crossed without evidence).
  const std::vector<TrackedLine> pieces = pieces_along(20, 8, 40, 1) + pieces_along(20, 52, 84, 11);
  // Events along both edges, and (in the second lattice) along the gap between them as well.
  ScarfLattice separate(SensorSize{128, 64}, kBlock, 2.0), one_edge(SensorSize{128, 64}, kBlock, 2.0);
  for (std::uint16_t x = 8; x <= 84; ++x) {
    if (x <= 40 || x >= 52) separate.insert(x, 20);
    one_edge.insert(x, 20);
  }
  const auto lines_with = [&](const ScarfLattice* events) {
    WholeLineTracker tracker(kBlock, publish_all());
    tracker.update(0, pieces, events);
    return tracker.lines().size();
  };
  EXPECT_EQ(lines_with(&separate), 2u);  // the gap holds no events: two edges
  EXPECT_EQ(lines_with(&one_edge), 1u);  // events run through it: one edge missing a segment
  EXPECT_EQ(lines_with(nullptr), 1u);    // no lattice: geometry alone joins them

  // Joined at one step, the two stay one line though the gap then holds no events (a line does not
  // split for a moment without events).
  WholeLineTracker tracker(kBlock, publish_all());
  tracker.update(0, pieces, &one_edge);
  tracker.update(1000, pieces, &separate);
  EXPECT_EQ(tracker.lines().size(), 1u);
}

// An L whose edges stop 10 px short of where they cross: with the lattice, they meet at the corner
// only where events run from each end to it (two edges that only nearly meet make no corner).
TEST(WholeLineTracker, LinesMeetAtACornerOnlyWhereTheEventsReachIt) {
  std::vector<TrackedLine> corner = pieces_along(20, 8, 40, 1);
  for (std::uint64_t k = 0; k < 4; ++k) {
    corner.push_back(segment(11 + k, 50, 30 + 8.0f * static_cast<float>(k), 50, 38 + 8.0f * static_cast<float>(k)));
  }
  ScarfLattice short_of_it(SensorSize{128, 96}, kBlock, 2.0), to_the_corner(SensorSize{128, 96}, kBlock, 2.0);
  for (std::uint16_t x = 8; x <= 50; ++x) {
    if (x <= 40) short_of_it.insert(x, 20);
    to_the_corner.insert(x, 20);
  }
  for (std::uint16_t y = 20; y <= 62; ++y) {
    if (y >= 30) short_of_it.insert(50, y);
    to_the_corner.insert(50, y);
  }
  const auto horizontal_end = [&](const ScarfLattice& events) {
    WholeLineTracker tracker(kBlock, without_event_reach());
    tracker.update(0, corner, &events);
    return max_x(line_holding(tracker, 20));
  };
  EXPECT_NEAR(horizontal_end(to_the_corner), 50.0f, 0.01f);
  EXPECT_NEAR(horizontal_end(short_of_it), 40.0f, 0.01f);
}

// A remembered end stays only while the events still run to it: an edge whose end the events left
// (it was cut short, or moved out of view) ends where its segments do.
TEST(WholeLineTracker, ARememberedEndStaysOnlyWhileTheEventsRunToIt) {
  ScarfLattice whole_edge(SensorSize{128, 64}, kBlock, 2.0), shorter(SensorSize{128, 64}, kBlock, 2.0);
  for (std::uint16_t x = 4; x <= 52; ++x) {
    whole_edge.insert(x, 20);
    if (x >= 12 && x <= 44) shorter.insert(x, 20);
  }
  const auto ends_after_the_ends_drop_out = [&](const ScarfLattice& events) {
    WholeLineTracker tracker(kBlock, without_event_reach());
    tracker.update(0, pieces_along(20, 4, 52, 1), &whole_edge);
    tracker.update(10, pieces_along(20, 12, 44, 2), &events);
    return std::pair(min_x(tracker.lines().at(0)), max_x(tracker.lines().at(0)));
  };
  const auto [kept_min, kept_max] = ends_after_the_ends_drop_out(whole_edge);
  EXPECT_NEAR(kept_min, 4.0f, 0.1f);
  EXPECT_NEAR(kept_max, 52.0f, 0.1f);
  const auto [left_min, left_max] = ends_after_the_ends_drop_out(shorter);
  EXPECT_NEAR(left_min, 12.0f, 0.1f);
  EXPECT_NEAR(left_max, 44.0f, 0.1f);
}

// ... and only as far as they go on: the right part of an edge whose segments dropped out over 4 b
// is kept to where its events end (runs without events of up to b are passed over), not to where
// its segments last reached nor dropped (the rule for a gap, half of the stretch held or nothing,
// would drop it: 16 of its 33 pixels are held).
TEST(WholeLineTracker, ARememberedEndIsKeptAsFarAsTheEventsGoOn) {
  ScarfLattice events(SensorSize{128, 64}, kBlock, 2.0);
  for (std::uint16_t x = 4; x <= 50; ++x) {
    if (x < 40 || x > 45) events.insert(x, 20);  // a 6 px run without events, passed over
  }
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces_along(20, 4, 68, 1), &events);
  tracker.update(10, pieces_along(20, 4, 36, 1), &events);
  const WholeLine& line = tracker.lines().at(0);
  EXPECT_NEAR(min_x(line), 4.0f, 0.1f);
  // The last event at x 50 holds the line to within 1.5 px + 0.1 px per px beyond its segments of it.
  EXPECT_GE(max_x(line), 50.0f);
  EXPECT_LE(max_x(line), 50.0f + 1.5f + 0.1f * 18.0f);
}

// An edge whose segments fall short of its end (the block there is not yet detected, or holds a
// corner) is published to where its events end, up to 2 b beyond its segments.
TEST(WholeLineTracker, AnEndReachesAlongTheEventsBeyondItsSegments) {
  ScarfLattice longer(SensorSize{128, 64}, kBlock, 2.0), as_long(SensorSize{128, 64}, kBlock, 2.0),
      much_longer(SensorSize{128, 64}, kBlock, 2.0);
  for (std::uint16_t x = 8; x <= 100; ++x) {
    if (x <= 52) longer.insert(x, 20);
    if (x <= 40) as_long.insert(x, 20);
    much_longer.insert(x, 20);
  }
  const auto end_with = [&](const ScarfLattice* events) {
    WholeLineTracker tracker(kBlock);
    tracker.update(0, pieces_along(20, 8, 40, 1), events);
    return max_x(tracker.lines().at(0));
  };
  // To the last event, or the pixel beyond it that an event 1 px away holds.
  EXPECT_GE(end_with(&longer), 52.0f);
  EXPECT_LE(end_with(&longer), 53.0f);
  EXPECT_LE(end_with(&as_long), 41.0f);
  EXPECT_NEAR(end_with(&much_longer), 40.0f + 2 * kBlock, 0.01f);
  EXPECT_NEAR(end_with(nullptr), 40.0f, 0.01f);
}

// Events on both sides of the stretch too are no edge going on: a band of noise, or of the trail an
// edge leaves where it moved across itself.
TEST(WholeLineTracker, AnEndDoesNotReachIntoABandOfEvents) {
  ScarfLattice band(SensorSize{128, 64}, kBlock, 4.0);
  for (std::uint16_t x = 8; x <= 40; ++x) band.insert(x, 20);
  for (std::uint16_t x = 41; x <= 56; ++x) {
    for (std::uint16_t y = 15; y <= 25; ++y) band.insert(x, y);
  }
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces_along(20, 8, 40, 1), &band);
  EXPECT_NEAR(max_x(line_holding(tracker, 20)), 40.0f, 0.01f);
}

// Nor does it reach into another published line: it stops 3 px short of it (its pixels are the other
// line's, and where the two make a corner, the corner rule joins them).
TEST(WholeLineTracker, AnEndStopsShortOfAnotherLine) {
  ScarfLattice events(SensorSize{128, 64}, kBlock, 2.0);
  for (std::uint16_t x = 8; x <= 70; ++x) events.insert(x, 20);
  std::vector<TrackedLine> pieces = pieces_along(20, 8, 40, 1);
  for (std::uint64_t k = 0; k < 6; ++k) {  // x = 50 from y = 0 to 48: its ends are 20 px or more from y = 20, no corner
    pieces.push_back(segment(21 + k, 50, 8.0f * static_cast<float>(k), 50, 8.0f * static_cast<float>(k + 1)));
  }
  WholeLineTracker tracker(kBlock);
  tracker.update(0, pieces, &events);
  ASSERT_EQ(tracker.lines().size(), 2u);
  EXPECT_NEAR(max_x(line_holding(tracker, 20)), 46.0f, 0.01f);
}

TEST(WholeLineTracker, RejectsStepsOutOfOrderAndABadBlockSize) {
  WholeLineTracker tracker(kBlock);
  tracker.update(10, {});
  EXPECT_THROW(tracker.update(9, {}), std::invalid_argument);
  EXPECT_THROW(WholeLineTracker(0), std::invalid_argument);
}

}  // namespace
}  // namespace evldt
