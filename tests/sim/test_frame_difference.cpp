#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "evldt/sim/frame_difference.hpp"
#include "evldt/sim/random.hpp"

namespace evldt {
namespace {

using Frame = std::vector<std::uint8_t>;

std::size_t pixel_count(SensorSize sensor) {
  return static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height);
}

Frame uniform_frame(SensorSize sensor, std::uint8_t value) { return Frame(pixel_count(sensor), value); }

Frame textured_frame(SensorSize sensor, SimRandom& random) {
  Frame frame(pixel_count(sensor));
  for (auto& v : frame) v = static_cast<std::uint8_t>(random.below(256));
  return frame;
}

// A bright vertical bar over columns [left, left + width) on a dark background.
Frame bar_frame(SensorSize sensor, int left, int width) {
  Frame frame = uniform_frame(sensor, 40);
  for (int y = 0; y < sensor.height; ++y) {
    for (int x = left; x < left + width; ++x) frame[static_cast<std::size_t>(y * sensor.width + x)] = 200;
  }
  return frame;
}

FrameDifferenceConfig exact_config() {
  FrameDifferenceConfig c;
  c.contrast_sigma = 0;
  return c;
}

// log(65 + 1) - log(39 + 1) = 0.5008: about 2.5 thresholds of 0.2.
constexpr std::uint8_t kDim = 39, kBright = 65;
const double kStep = std::log(66.0 / 40.0);

TEST(FrameDifferenceEmulator, StaticImageGivesNoEvents) {
  const SensorSize sensor{16, 12};
  SimRandom random(3);
  const Frame frame = textured_frame(sensor, random);
  FrameDifferenceEmulator emulator(sensor, FrameDifferenceConfig{});
  EventBatch out;
  for (int k = 0; k < 5; ++k) emulator.add_frame(frame, 1000 + k * 33333, out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(emulator.frames(), 5u);
  EXPECT_EQ(emulator.events(), 0u);
}

TEST(FrameDifferenceEmulator, FirstFrameOnlySetsTheReference) {
  const SensorSize sensor{8, 6};
  FrameDifferenceEmulator emulator(sensor, exact_config());
  EventBatch out;
  emulator.add_frame(uniform_frame(sensor, 250), 0, out);  // far from any earlier state, yet no events
  EXPECT_TRUE(out.empty());
  emulator.add_frame(uniform_frame(sensor, 250), 10, out);
  EXPECT_TRUE(out.empty());
}

TEST(FrameDifferenceEmulator, BrighteningStepGivesOneEventPerThresholdAtInterpolatedTimes) {
  const SensorSize sensor{8, 6};
  const std::size_t pixels = pixel_count(sensor);
  FrameDifferenceEmulator emulator(sensor, exact_config());
  EventBatch out;
  emulator.add_frame(uniform_frame(sensor, kDim), 1000, out);
  emulator.add_frame(uniform_frame(sensor, kBright), 2000, out);
  ASSERT_EQ(out.size(), 2 * pixels);
  EXPECT_EQ(emulator.events(), 2 * pixels);
  // Crossings of +0.2 and +0.4 along a linear change of kStep over 1000 us; every pixel's first
  // event comes before any pixel's second, and equal times stay in pixel order.
  for (std::size_t k = 0; k < 2; ++k) {
    const double expected_t = 1000 + 1000 * 0.2 * static_cast<double>(k + 1) / kStep;
    for (std::size_t i = 0; i < pixels; ++i) {
      const Event e = out[k * pixels + i];
      EXPECT_NEAR(static_cast<double>(e.t), expected_t, 1.0);
      EXPECT_EQ(e.t, out.t[k * pixels]);
      EXPECT_EQ(e.x, i % static_cast<std::size_t>(sensor.width));
      EXPECT_EQ(e.y, i / static_cast<std::size_t>(sensor.width));
      EXPECT_EQ(e.p, 1);
    }
  }
}

TEST(FrameDifferenceEmulator, DarkeningStepGivesNegativePolarity) {
  const SensorSize sensor{8, 6};
  FrameDifferenceEmulator emulator(sensor, exact_config());
  EventBatch out;
  emulator.add_frame(uniform_frame(sensor, kBright), 0, out);
  emulator.add_frame(uniform_frame(sensor, kDim), 1000, out);
  ASSERT_EQ(out.size(), 2 * pixel_count(sensor));
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out.p[i], -1);
  EXPECT_NEAR(static_cast<double>(out.t.front()), 1000 * 0.2 / kStep, 1.0);
  EXPECT_NEAR(static_cast<double>(out.t.back()), 1000 * 0.4 / kStep, 1.0);
}

TEST(FrameDifferenceEmulator, MovingBarFiresOnlyAtItsLeadingAndTrailingColumns) {
  const SensorSize sensor{24, 6};
  FrameDifferenceEmulator emulator(sensor, FrameDifferenceConfig{});
  EventBatch out;
  emulator.add_frame(bar_frame(sensor, 4, 4), 0, out);
  for (int left = 5; left <= 15; ++left) {
    out.clear();
    emulator.add_frame(bar_frame(sensor, left, 4), left * 10000, out);
    ASSERT_FALSE(out.empty());
    std::set<int> leading_rows, trailing_rows;
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (out.x[i] == left + 3) {  // newly covered by the bar: brighter
        EXPECT_EQ(out.p[i], 1);
        leading_rows.insert(out.y[i]);
      } else if (out.x[i] == left - 1) {  // just uncovered: darker
        EXPECT_EQ(out.p[i], -1);
        trailing_rows.insert(out.y[i]);
      } else {
        ADD_FAILURE() << "event at column " << out.x[i] << " with the bar over [" << left << ", " << left + 3 << "]";
      }
    }
    EXPECT_EQ(leading_rows.size(), static_cast<std::size_t>(sensor.height));
    EXPECT_EQ(trailing_rows.size(), static_cast<std::size_t>(sensor.height));
  }
}

TEST(FrameDifferenceEmulator, AppendsEventsInTimeOrderInsideEachFrameInterval) {
  const SensorSize sensor{40, 30};
  FrameDifferenceConfig config;
  config.refractory_us = 0;
  SimRandom random(11);
  std::vector<Frame> frames;
  for (int k = 0; k < 6; ++k) frames.push_back(textured_frame(sensor, random));
  // Intervals from 1 us to 5 s, so the time sort takes one to three radix passes.
  const std::vector<Timestamp> times = {-500, 32833, 32834, 32841, 5032841, 5072841};

  FrameDifferenceEmulator emulator(sensor, config), regular(sensor, config);
  const Event sentinel{-1000, 1, 2, 1};
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EventBatch out, regular_out;
    out.push_back(sentinel);
    emulator.add_frame(frames[k], times[k], out);
    regular.add_frame(frames[k], static_cast<Timestamp>(k) * 1000000, regular_out);
    ASSERT_EQ(out[0], sentinel);
    if (k == 0) {
      EXPECT_EQ(out.size(), 1u);
      continue;
    }
    ASSERT_GT(out.size(), 1000u);
    for (std::size_t i = 1; i < out.size(); ++i) {
      ASSERT_GT(out.t[i], times[k - 1]);
      ASSERT_LE(out.t[i], times[k]);
      if (i > 1) {
        ASSERT_LE(std::tie(out.t[i - 1], out.y[i - 1], out.x[i - 1]), std::tie(out.t[i], out.y[i], out.x[i]))
            << "frame " << k << " event " << i;
      }
    }
    // With no refractory losses the interval moves events in time but neither adds nor drops any.
    std::vector<std::tuple<int, int, int>> pixels, regular_pixels;
    for (std::size_t i = 1; i < out.size(); ++i) pixels.emplace_back(out.y[i], out.x[i], out.p[i]);
    for (std::size_t i = 0; i < regular_out.size(); ++i) {
      regular_pixels.emplace_back(regular_out.y[i], regular_out.x[i], regular_out.p[i]);
    }
    std::sort(pixels.begin(), pixels.end());
    std::sort(regular_pixels.begin(), regular_pixels.end());
    EXPECT_EQ(pixels, regular_pixels) << "frame " << k;
  }
  EXPECT_EQ(emulator.events(), regular.events());
}

EventBatch emulate(SensorSize sensor, const FrameDifferenceConfig& config, const std::vector<Frame>& frames) {
  FrameDifferenceEmulator emulator(sensor, config);
  EventBatch out;
  for (std::size_t k = 0; k < frames.size(); ++k) emulator.add_frame(frames[k], static_cast<Timestamp>(k) * 20000, out);
  return out;
}

TEST(FrameDifferenceEmulator, SameSeedSameEventsOtherSeedOthers) {
  const SensorSize sensor{32, 24};
  SimRandom random(5);
  std::vector<Frame> frames;
  for (int k = 0; k < 4; ++k) frames.push_back(textured_frame(sensor, random));
  FrameDifferenceConfig config;
  config.contrast_sigma = 0.05;
  config.seed = 7;
  const EventBatch a = emulate(sensor, config, frames), b = emulate(sensor, config, frames);
  ASSERT_GT(a.size(), 1000u);
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.p, b.p);
  config.seed = 8;
  const EventBatch c = emulate(sensor, config, frames);
  EXPECT_TRUE(a.t != c.t || a.x != c.x || a.y != c.y || a.p != c.p);
}

TEST(FrameDifferenceEmulator, RefractoryDropsEventsButStillMovesTheReference) {
  const SensorSize sensor{4, 3};
  const std::size_t pixels = pixel_count(sensor);
  FrameDifferenceConfig config = exact_config();
  config.refractory_us = 300;
  FrameDifferenceEmulator emulator(sensor, config);
  EventBatch out;
  emulator.add_frame(uniform_frame(sensor, kDim), 0, out);
  // Crossings at ~200 us and ~400 us: the second is within 300 us of the first and is lost.
  emulator.add_frame(uniform_frame(sensor, kBright), 500, out);
  ASSERT_EQ(out.size(), pixels);
  for (std::size_t i = 0; i < pixels; ++i) EXPECT_NEAR(static_cast<double>(out.t[i]), 500 * 0.2 / kStep, 1.0);
  EXPECT_EQ(emulator.events(), pixels);
  // log(77 / 40) = 0.655 above the start: only the +0.6 level is left, as the lost event moved the
  // reference to +0.4 (without that move +0.4 would fire again).
  out.clear();
  emulator.add_frame(uniform_frame(sensor, 76), 20000, out);
  EXPECT_EQ(out.size(), pixels);

  // A longer interval than the refractory period keeps both.
  config.refractory_us = 100;
  FrameDifferenceEmulator relaxed(sensor, config);
  out.clear();
  relaxed.add_frame(uniform_frame(sensor, kDim), 0, out);
  relaxed.add_frame(uniform_frame(sensor, kBright), 500, out);
  EXPECT_EQ(out.size(), 2 * pixels);
}

TEST(FrameDifferenceEmulator, RejectsWrongFrameSizeAndNonIncreasingTime) {
  const SensorSize sensor{8, 6};
  FrameDifferenceEmulator emulator(sensor, exact_config());
  EventBatch out;
  EXPECT_THROW(emulator.add_frame(Frame(47, kDim), 0, out), std::invalid_argument);
  EXPECT_THROW(emulator.add_frame(Frame(49, kDim), 0, out), std::invalid_argument);
  EXPECT_EQ(emulator.frames(), 0u);
  emulator.add_frame(uniform_frame(sensor, kDim), 1000, out);
  EXPECT_THROW(emulator.add_frame(uniform_frame(sensor, kBright), 1000, out), std::invalid_argument);
  EXPECT_THROW(emulator.add_frame(uniform_frame(sensor, kBright), 999, out), std::invalid_argument);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(emulator.frames(), 1u);
  // The rejected frames left the state alone: the step still gives its two events per pixel.
  emulator.add_frame(uniform_frame(sensor, kBright), 2000, out);
  EXPECT_EQ(out.size(), 2 * pixel_count(sensor));
}

TEST(FrameDifferenceEmulator, RejectsInvalidConfiguration) {
  FrameDifferenceConfig config;
  EXPECT_THROW(FrameDifferenceEmulator({0, 6}, config), std::invalid_argument);
  EXPECT_THROW(FrameDifferenceEmulator({70000, 1}, config), std::invalid_argument);
  config.contrast_off = 0;
  EXPECT_THROW(FrameDifferenceEmulator({8, 6}, config), std::invalid_argument);
  config = {};
  config.log_offset = 0;  // log(0) for black
  EXPECT_THROW(FrameDifferenceEmulator({8, 6}, config), std::invalid_argument);
  config = {};
  config.refractory_us = -1;
  EXPECT_THROW(FrameDifferenceEmulator({8, 6}, config), std::invalid_argument);
}

}  // namespace
}  // namespace evldt
