#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "evldt/scarf/scarf_lattice.hpp"
#include "support/sweeping_edge.hpp"

namespace evldt {
namespace {

constexpr SensorSize kSensor{64, 48};  // b = 8: 7 x 5 blocks, lattice from 4 to 60 (x) and 4 to 44 (y)

TEST(LatticeGeometry, TilesWithHalfBlockMargin) {
  const auto g = LatticeGeometry::make(kSensor, 8, 1.0);
  EXPECT_EQ(g.blocks_x, 7);
  EXPECT_EQ(g.blocks_y, 5);
  EXPECT_EQ(g.capacity, 32);
  EXPECT_EQ(g.min_points(), 3);
  EXPECT_EQ(g.block_at(4.0f, 4.0f), g.index(0, 0));
  EXPECT_EQ(g.block_at(3.99f, 10.0f), -1);
  EXPECT_EQ(g.block_at(59.99f, 43.99f), g.index(6, 4));
  EXPECT_EQ(g.block_at(60.0f, 20.0f), -1);
  EXPECT_EQ(LatticeGeometry::make({640, 480}, 14, 1.0).capacity, 98);
  EXPECT_EQ(LatticeGeometry::make({640, 480}, 14, 0.5).capacity, 49);
}

TEST(LatticeGeometry, RejectsUnusableParameters) {
  EXPECT_THROW(LatticeGeometry::make({0, 48}, 8, 1.0), std::invalid_argument);
  EXPECT_THROW(LatticeGeometry::make({64, 48}, 7, 1.0), std::invalid_argument);
  EXPECT_THROW(LatticeGeometry::make({64, 48}, 64, 1.0), std::invalid_argument);
  EXPECT_THROW(LatticeGeometry::make({64, 48}, 8, -1.0), std::invalid_argument);
  EXPECT_THROW(LatticeGeometry::make({64, 48}, 8, std::nan("")), std::invalid_argument);
  EXPECT_THROW(LatticeGeometry::make({40000, 48}, 8, 1.0), std::invalid_argument);
}

// Which blocks got an entry for a pixel, and with which flag.
std::set<std::pair<int, bool>> blocks_written(std::uint16_t x, std::uint16_t y) {
  ScarfLattice lattice(kSensor, 8, 1.0);
  lattice.insert(x, y);
  std::set<std::pair<int, bool>> written;
  for (int block = 0; block < lattice.geometry().block_count(); ++block) {
    const BlockEntries view = lattice.entries(block);
    for (const LatticeEntry& e : view.entries) {
      EXPECT_EQ(view.pixel_x(e), x);
      EXPECT_EQ(view.pixel_y(e), y);
      written.insert({block, e.active()});
    }
  }
  return written;
}

TEST(ScarfLattice, ActiveInHomeBlockInactiveInThreeQuadrantNeighbours) {
  const auto g = LatticeGeometry::make(kSensor, 8, 1.0);
  // Pixel 13 is in block column 1 ([12, 20)), left half -> column 0; pixel 21 in row 2 ([20, 28)), top half -> row 1.
  const std::set<std::pair<int, bool>> expected{
      {g.index(1, 2), true}, {g.index(0, 2), false}, {g.index(1, 1), false}, {g.index(0, 1), false}};
  EXPECT_EQ(blocks_written(13, 21), expected);
  // Right/bottom halves pick the other side.
  const std::set<std::pair<int, bool>> expected_other{
      {g.index(1, 2), true}, {g.index(2, 2), false}, {g.index(1, 3), false}, {g.index(2, 3), false}};
  EXPECT_EQ(blocks_written(17, 25), expected_other);
}

// Detection's retry gate counts the active entries that came into a block since its last refusal.
TEST(ScarfLattice, ActiveArrivalsCountTheActiveEntriesWrittenIntoABlock) {
  ScarfLattice lattice(kSensor, 8, 1.0);
  const auto g = lattice.geometry();
  for (int k = 0; k < 100; ++k) lattice.insert(13, 21);    // active in block (1, 2), inactive in three others
  EXPECT_EQ(lattice.active_arrivals(g.index(1, 2)), 100);  // all of them, past the ring's N = 32
  EXPECT_EQ(lattice.active_count(g.index(1, 2)), 32);
  EXPECT_EQ(lattice.active_arrivals(g.index(0, 2)), 0);    // inactive entries do not count
  for (int k = 0; k < 65536; ++k) lattice.insert(13, 21);  // modulo 2^16
  EXPECT_EQ(lattice.active_arrivals(g.index(1, 2)), 100);
}

TEST(ScarfLattice, MarginPixelsAreOnlyInactive) {
  const auto g = LatticeGeometry::make(kSensor, 8, 1.0);
  // Top-left margin corner pixel: inside block (0,0)'s extended region only.
  EXPECT_EQ(blocks_written(1, 2), (std::set<std::pair<int, bool>>{{g.index(0, 0), false}}));
  // Left margin, row 2 bottom half: blocks (0,2) and (0,3), inactive.
  EXPECT_EQ(blocks_written(0, 26), (std::set<std::pair<int, bool>>{{g.index(0, 2), false}, {g.index(0, 3), false}}));
  // Lattice edge column: the last block has no right neighbour.
  EXPECT_EQ(blocks_written(59, 30), (std::set<std::pair<int, bool>>{{g.index(6, 3), true}, {g.index(6, 2), false}}));
  // The last row of this sensor is still inside row 4's extended band.
  EXPECT_EQ(blocks_written(30, 47), (std::set<std::pair<int, bool>>{{g.index(3, 4), false}, {g.index(2, 4), false}}));
  // On a 70 px wide sensor the right margin is 10 px: its outer pixels belong to no block.
  ScarfLattice wide({70, 48}, 8, 1.0);
  wide.insert(66, 20);
  for (int block = 0; block < wide.geometry().block_count(); ++block) EXPECT_TRUE(wide.entries(block).entries.empty());
}

TEST(ScarfLattice, RingKeepsNewestNAndCountsActive) {
  ScarfLattice lattice(kSensor, 8, 1.0, /*keep_surface=*/true);
  const auto& g = lattice.geometry();
  const int block = g.index(3, 2);
  for (int k = 0; k < 40; ++k) lattice.insert(static_cast<std::uint16_t>(30 + k % 2), 22);  // 40 active events
  EXPECT_EQ(lattice.entries(block).entries.size(), 32u);
  EXPECT_EQ(lattice.active_count(block), 32);
  EXPECT_EQ(lattice.surface()[22 * 64 + 30] + lattice.surface()[22 * 64 + 31], 32);
  // Inactive writes from the neighbour below push the active ones out one by one.
  for (int k = 0; k < 10; ++k) lattice.insert(30, 28);  // row 3, top half -> inactive in row 2
  EXPECT_EQ(lattice.active_count(block), 22);
  EXPECT_EQ(lattice.surface()[22 * 64 + 30] + lattice.surface()[22 * 64 + 31], 22);
  EXPECT_EQ(lattice.surface()[28 * 64 + 30], 10);  // active in its own block (3,3)
}

TEST(ScarfLattice, CopyStateGivesAnIdenticalView) {
  ScarfLattice source(kSensor, 8, 1.0), copy(kSensor, 8, 1.0);
  for (int k = 0; k < 500; ++k)
    source.insert(static_cast<std::uint16_t>(k * 7 % 64), static_cast<std::uint16_t>(k * 5 % 48));
  copy.copy_state_from(source);
  for (int block = 0; block < source.geometry().block_count(); ++block) {
    ASSERT_EQ(copy.active_count(block), source.active_count(block));
    const auto a = source.entries(block).entries, b = copy.entries(block).entries;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].bits, b[i].bits);
  }
  ScarfLattice other(SensorSize{64, 64}, 8, 1.0);
  EXPECT_THROW(other.copy_state_from(source), std::invalid_argument);
}

void expect_same_rings(const ScarfLattice& a, const ScarfLattice& b) {
  for (int block = 0; block < a.geometry().block_count(); ++block) {
    ASSERT_EQ(a.active_count(block), b.active_count(block)) << block;
    ASSERT_EQ(a.active_arrivals(block), b.active_arrivals(block)) << block;
    const auto ea = a.entries(block).entries, eb = b.entries(block).entries;
    ASSERT_EQ(ea.size(), eb.size()) << block;
    for (std::size_t i = 0; i < ea.size(); ++i) ASSERT_EQ(ea[i].bits, eb[i].bits) << block;
  }
}

TEST(ScarfLattice, InsertingCopiesEndsAsInsertingEachEventThatManyTimes) {
  for (const int copies : {2, 3, 4}) {
    ScarfLattice in_copies(kSensor, 8, 1.0, /*keep_surface=*/true), one_by_one(kSensor, 8, 1.0, /*keep_surface=*/true);
    std::vector<std::uint16_t> xs, ys;
    for (int k = 0; k < 700; ++k) {  // enough to wrap every ring (N = 32) several times over
      xs.push_back(static_cast<std::uint16_t>((k * 37 + k / 7) % 64));
      ys.push_back(static_cast<std::uint16_t>((k * 11 + k / 5) % 48));
    }
    in_copies.insert(xs, ys, copies);
    for (std::size_t i = 0; i < xs.size(); ++i) {
      for (int c = 0; c < copies; ++c) one_by_one.insert(xs[i], ys[i]);
    }
    expect_same_rings(in_copies, one_by_one);
    EXPECT_EQ(in_copies.surface(), one_by_one.surface()) << copies;
  }
}

// What copies do for a thinned stream (the service's rule: RealtimeEngine::stored_copies): every 2nd
// event, kept once, fills a ring at half the pace, so the ring reaches twice as far back in time and
// still holds an edge that has moved on; stored twice, it reaches back as far as the whole stream's.
TEST(ScarfLattice, AThinnedStreamStoredInCopiesReachesBackAsFarAsTheWholeStream) {
  const SensorSize sensor{240, 180};
  // A vertical edge moving right, stopped while it crosses block column 10 (x from 84 to 92).
  const auto events = testing::sweep_events({Point2(20, 0), Point2(20, 180), Point2(100, 0), 0, 680'000}, sensor);
  EventBatch every_second;
  for (std::size_t i = 1; i < events.size(); i += 2) every_second.push_back(events[i]);
  ScarfLattice whole(sensor, 8, 1.0), once(sensor, 8, 1.0), twice(sensor, 8, 1.0);
  whole.insert(events);
  once.insert(every_second.x, every_second.y);
  twice.insert(every_second.x, every_second.y, 2);
  // The oldest x a block's ring still holds in row 10: the edge's trail behind it.
  const auto oldest_x = [](const ScarfLattice& lattice, int block) {
    const BlockEntries entries = lattice.entries(block);
    int oldest = 1 << 20;
    for (const LatticeEntry e : entries.entries) oldest = std::min(oldest, entries.pixel_x(e));
    return oldest;
  };
  const int block = whole.geometry().index(10, 10);
  EXPECT_EQ(oldest_x(twice, block), oldest_x(whole, block));
  EXPECT_LT(oldest_x(once, block), oldest_x(whole, block));
}

TEST(ScarfLattice, IncrementalCopyFollowsEveryChange) {
  ScarfLattice source(kSensor, 8, 1.0), view(kSensor, 8, 1.0);
  const auto write = [&](int count, int seed) {
    for (int k = 0; k < count; ++k) {
      source.insert(static_cast<std::uint16_t>((k * 7 + seed) % 64),
                    static_cast<std::uint16_t>((k * 5 + seed * 3) % 48));
    }
  };
  write(500, 0);
  view.copy_state_from(source);
  expect_same_rings(source, view);
  // A few events touch a few blocks: the view follows them (and the ring wrap) exactly.
  for (int round = 1; round < 40; ++round) {
    source.insert(static_cast<std::uint16_t>(round % 64), 20);
    view.copy_state_from(source);
    expect_same_rings(source, view);
  }
  // A clear, then writes bringing the versions of a cleared block back to any count.
  source.clear();
  view.copy_state_from(source);
  expect_same_rings(source, view);
  write(300, 1);
  view.copy_state_from(source);
  expect_same_rings(source, view);
  // A view written to itself, or updated from another lattice, is copied in full next time.
  view.insert(30, 20);
  view.copy_state_from(source);
  expect_same_rings(source, view);
  ScarfLattice other(kSensor, 8, 1.0);
  for (int k = 0; k < 300; ++k) other.insert(static_cast<std::uint16_t>(k % 64), static_cast<std::uint16_t>(k % 48));
  view.copy_state_from(other);
  expect_same_rings(other, view);
  view.copy_state_from(source);
  expect_same_rings(source, view);
}

TEST(ScarfLattice, AVersionChangesWhenItsBlockChangesAndOnlyThen) {
  ScarfLattice lattice(kSensor, 8, 1.0);
  const int block = lattice.geometry().index(3, 2);  // holds pixel (30, 22) actively
  const int elsewhere = lattice.geometry().index(0, 0);
  const std::uint64_t before = lattice.version(block);
  const std::uint64_t elsewhere_before = lattice.version(elsewhere);
  lattice.insert(30, 22);
  const std::uint64_t once = lattice.version(block);
  EXPECT_NE(once, before);
  EXPECT_EQ(lattice.version(elsewhere), elsewhere_before);
  lattice.insert(30, 22);  // the same event again still advances the ring
  EXPECT_NE(lattice.version(block), once);
  const std::uint64_t twice = lattice.version(block);
  lattice.clear();
  EXPECT_NE(lattice.version(block), twice);
  EXPECT_NE(lattice.version(elsewhere), elsewhere_before);  // a clear changes every block
}

// Versions compare only under one versions_of(): a copy changed after the copy must not claim the
// numbering it had before, nor that of its source.
TEST(ScarfLattice, ACopyChangedAfterwardsNumbersItsVersionsApart) {
  ScarfLattice source(kSensor, 8, 1.0);
  ScarfLattice copy(kSensor, 8, 1.0);
  copy.insert(30, 22);
  const std::uint64_t copy_numbering = copy.versions_of();
  copy.copy_state_from(source);
  EXPECT_EQ(copy.versions_of(), source.versions_of());
  copy.insert(30, 22);
  EXPECT_NE(copy.versions_of(), copy_numbering);
  EXPECT_NE(copy.versions_of(), source.versions_of());
}

// An edge crossing the sensor at speed v leaves (per block it has passed) the same active entries
// whatever v: the ring holds a fixed number of events, not a time window.
TEST(ScarfLattice, ActiveEntriesPerBlockDoNotDependOnEdgeSpeed) {
  const SensorSize sensor{240, 180};
  auto active_per_block = [&](float speed) {
    ScarfLattice lattice(sensor, 8, 1.0);
    // Vertical edge from x=20 moving right; stop when it has reached x=100.
    const float seconds = 80.0f / speed;
    const auto events = testing::sweep_events(
        {Point2(20, 0), Point2(20, 180), Point2(speed, 0), 0, static_cast<Timestamp>(seconds * 1e6)}, sensor);
    lattice.insert(events);
    std::vector<int> counts;
    for (int block = 0; block < lattice.geometry().block_count(); ++block)
      counts.push_back(lattice.active_count(block));
    return counts;
  };
  const auto slow = active_per_block(100.0f);
  const auto fast = active_per_block(1000.0f);
  EXPECT_EQ(slow, fast);
  // Behind the edge, inactive entries have cleared the blocks: only the 21 blocks of its column hold it.
  int touched = 0;
  for (const int c : slow) touched += c > 0 ? 1 : 0;
  EXPECT_EQ(touched, 21);
}

TEST(ScarfLattice, InactiveEntriesClearABlockAfterTheEdgeLeaves) {
  const SensorSize sensor{240, 180};
  ScarfLattice lattice(sensor, 8, 1.0);
  const auto& g = lattice.geometry();
  const int block = g.index(5, 10);  // x in [44, 52)
  // Edge sweeps from x=30 through the block and stops at x=56: 4 px past it, inside the half-block band.
  lattice.insert(testing::sweep_events({Point2(30, 0), Point2(30, 180), Point2(100, 0), 0, 260000}, sensor));
  EXPECT_EQ(lattice.active_count(block), 0);
  // Stopping inside the block leaves its active entries.
  ScarfLattice inside(sensor, 8, 1.0);
  inside.insert(testing::sweep_events({Point2(30, 0), Point2(30, 180), Point2(100, 0), 0, 200000}, sensor));
  EXPECT_GT(inside.active_count(block), g.min_points());
}

}  // namespace
}  // namespace evldt
