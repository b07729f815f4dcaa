#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "evldt/lines/event_pixels.hpp"

namespace evldt {
namespace {

/// What EventPixels answers from its maps, by a scan of the block's entries.
bool any_within_by_scan(const ScarfLattice& lattice, Point2 at, float radius) {
  const int block = lattice.geometry().block_at(at.x(), at.y());
  if (block < 0) return false;
  const float r = std::min(radius, 0.5f * static_cast<float>(lattice.geometry().block_size));
  const BlockEntries entries = lattice.entries(block);
  for (const LatticeEntry e : entries.entries) {
    const float dx = static_cast<float>(entries.pixel_x(e)) - at.x(),
                dy = static_cast<float>(entries.pixel_y(e)) - at.y();
    if (dx * dx + dy * dy <= r * r) return true;
  }
  return false;
}

TEST(EventPixels, AnswersAsAScanOfTheBlocksEntriesWouldAcrossSteps) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> x_of(0, 99), y_of(0, 79);
  std::uniform_real_distribution<float> point_x(-5, 105), point_y(-5, 85), radius_of(0, 6);
  ScarfLattice lattice(SensorSize{100, 80}, 10, 1.0);
  EventPixels pixels;
  int hits = 0, asked = 0;
  for (int step = 0; step < 5; ++step) {
    // Each step changes the lattice: a map made at the last step must not answer for this one.
    for (int i = 0; i < 400; ++i)
      lattice.insert(static_cast<std::uint16_t>(x_of(random)), static_cast<std::uint16_t>(y_of(random)));
    pixels.reset(&lattice);
    for (int q = 0; q < 2000; ++q) {
      const Point2 at(point_x(random), point_y(random));
      const float radius = radius_of(random);
      const bool expected = any_within_by_scan(lattice, at, radius);
      ASSERT_EQ(pixels.any_within(at, radius), expected)
          << "at (" << at.x() << ", " << at.y() << "), radius " << radius;
      hits += expected ? 1 : 0;
      ++asked;
    }
  }
  // Both answers were asked for many times.
  EXPECT_GT(hits, asked / 10);
  EXPECT_LT(hits, asked - asked / 10);
}

TEST(EventPixels, WithoutALatticeHoldsNoEvent) {
  ScarfLattice lattice(SensorSize{100, 80}, 10, 1.0);
  lattice.insert(50, 40);
  EventPixels pixels;
  pixels.reset(&lattice);
  EXPECT_TRUE(pixels.any_within(Point2(50, 40), 1));
  pixels.reset(nullptr);
  EXPECT_FALSE(pixels.any_within(Point2(50, 40), 1));
}

}  // namespace
}  // namespace evldt
