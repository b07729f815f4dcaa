#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <utility>

#include "evldt/lines/bend_test.hpp"
#include "evldt/lines/detector.hpp"

namespace evldt {
namespace {

constexpr SensorSize kSensor{240, 180};
constexpr int kBlock = 10;

using Pixels = std::vector<std::pair<int, int>>;

// The pixels of a drawn edge, in drawing order, each once.
void add_pixel(Pixels& pixels, std::set<std::pair<int, int>>& seen, double x, double y) {
  const std::pair<int, int> pixel(static_cast<int>(std::floor(x)), static_cast<int>(std::floor(y)));
  if (seen.insert(pixel).second) pixels.push_back(pixel);
}

Pixels circle(double cx, double cy, double radius) {
  Pixels pixels;
  std::set<std::pair<int, int>> seen;
  for (int k = 0; k < 4000; ++k) {
    const double angle = 2 * std::numbers::pi * k / 4000;
    add_pixel(pixels, seen, cx + radius * std::cos(angle), cy + radius * std::sin(angle));
  }
  return pixels;
}

Pixels polyline(const std::vector<std::pair<double, double>>& corners) {
  Pixels pixels;
  std::set<std::pair<int, int>> seen;
  for (std::size_t c = 0; c + 1 < corners.size(); ++c) {
    const auto [x0, y0] = corners[c];
    const auto [x1, y1] = corners[c + 1];
    const int steps = static_cast<int>(4 * std::hypot(x1 - x0, y1 - y0));
    for (int k = 0; k <= steps; ++k) add_pixel(pixels, seen, x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps);
  }
  return pixels;
}

// Every pixel twice, as an edge sweeping past would leave it.
void store(ScarfLattice& lattice, const Pixels& pixels) {
  for (int pass = 0; pass < 2; ++pass) {
    for (const auto& [x, y] : pixels) lattice.insert(static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y));
  }
}

std::vector<Segment> detect(const ScarfLattice& lattice, float max_bend_ratio, bool test_bends = true) {
  ScoreParams params;
  params.max_bend_ratio = max_bend_ratio;
  LineDetector detector(lattice.geometry(), params);
  LineMap lines(lattice.geometry());
  detector.detect(lattice, lines, 0, test_bends);
  std::vector<Segment> found;
  for (const TrackedLine& line : lines.lines()) found.push_back(line.segment);
  return found;
}

TEST(BendTest, ArcsOfACircleAreNotDetected) {
  ScarfLattice lattice(kSensor, kBlock, 1.0);
  store(lattice, circle(120, 90, 45));  // 4.5 blocks: within one block the arc is 0.3 px off its chord
  const std::vector<Segment> without_test = detect(lattice, 0.0f);
  ASSERT_GE(without_test.size(), 12u) << "the arc's blocks fit lines: the case the test is for";
  BendTest bend(lattice.geometry(), ScoreParams{}.max_bend_ratio);
  int bent = 0;
  for (const Segment& segment : without_test) bent += bend.bent(lattice, segment) ? 1 : 0;
  EXPECT_GE(bent, static_cast<int>(without_test.size()) * 3 / 4);
  EXPECT_LE(detect(lattice, ScoreParams{}.max_bend_ratio).size(), without_test.size() / 4);
}

// The live engine skips the test while it sheds: a round then keeps the arc's lines as if the
// test were off.
TEST(BendTest, ARoundMaySkipTheTest) {
  ScarfLattice lattice(kSensor, kBlock, 1.0);
  store(lattice, circle(120, 90, 45));
  EXPECT_EQ(detect(lattice, ScoreParams{}.max_bend_ratio, /*test_bends=*/false).size(), detect(lattice, 0.0f).size());
}

TEST(BendTest, StraightEdgesKeepTheirLinesAtCornersJunctionsAndNeighbours) {
  ScarfLattice lattice(kSensor, kBlock, 1.0);
  store(lattice, polyline({{40.3, 30.6}, {200.2, 30.6}, {200.2, 150.4}, {40.3, 150.4}, {40.3, 30.6}}));  // a box
  store(lattice, polyline({{120.5, 30.6}, {120.5, 100.0}}));  // a T on its top edge
  store(lattice, polyline({{60.0, 60.2}, {180.0, 73.0}}));    // a slanted edge
  store(lattice, polyline({{60.0, 120.4}, {180.0, 120.4}}));  // two edges 3 px apart
  store(lattice, polyline({{60.0, 123.4}, {180.0, 123.4}}));
  const std::vector<Segment> without_test = detect(lattice, 0.0f);
  ASSERT_GE(without_test.size(), 40u);
  BendTest bend(lattice.geometry(), ScoreParams{}.max_bend_ratio);
  for (const Segment& segment : without_test) {
    EXPECT_FALSE(bend.bent(lattice, segment)) << segment.q0.transpose() << " - " << segment.q1.transpose();
  }
  EXPECT_EQ(detect(lattice, ScoreParams{}.max_bend_ratio).size(), without_test.size());
}

}  // namespace
}  // namespace evldt
