// The noise filters on hand-made streams with known answers.

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <tuple>

#include "evldt/filters/filter_chain.hpp"

namespace evldt {
namespace {

constexpr SensorSize kSensor{64, 48};

struct Tagged {
  Event event;
  int tag;  // which source made it, so a test can count what passed of each
};

EventBatch batch_of(std::vector<Tagged>& events) {
  std::stable_sort(events.begin(), events.end(),
                   [](const Tagged& a, const Tagged& b) { return a.event.t < b.event.t; });
  EventBatch batch;
  for (const Tagged& e : events) batch.push_back(e.event);
  return batch;
}

/// A chain of the one filter `name`, with `config`'s parameters.
FilterChain only(const std::string& name, FilterConfig config = {}) {
  config.chain = {name};
  return FilterChain(config, kSensor);
}

/// Runs `filter` over the stream in batches of `batch_size` and counts what passed of each tag.
std::map<int, std::pair<int, int>> passed_by_tag(FilterChain& filter, std::vector<Tagged> events,
                                                 std::size_t batch_size = 97) {
  const EventBatch all = batch_of(events);
  std::map<std::tuple<Timestamp, int, int, int>, int> tag_of;
  std::map<int, std::pair<int, int>> counts;  // tag -> (passed, total)
  for (const Tagged& e : events) {
    tag_of[{e.event.t, e.event.x, e.event.y, e.event.p}] = e.tag;
    ++counts[e.tag].second;
  }
  for (std::size_t at = 0; at < all.size(); at += batch_size) {
    EventBatch batch;
    for (std::size_t i = at; i < std::min(all.size(), at + batch_size); ++i) batch.push_back(all[i]);
    filter.filter(batch, batch);
    for (std::size_t i = 0; i < batch.size(); ++i)
      ++counts[tag_of.at({batch.t[i], batch.x[i], batch.y[i], batch.p[i]})].first;
  }
  return counts;
}

/// A vertical edge sweeping right: column c fires (every row, ON) at t0 + c * column_us.
void add_sweeping_edge(std::vector<Tagged>& events, Timestamp t0, Timestamp column_us, int tag, int x_first = 0,
                       int x_last = kSensor.width - 1) {
  for (int x = x_first; x <= x_last; ++x) {
    for (int y = 0; y < kSensor.height; ++y) {
      events.push_back(
          {{t0 + (x - x_first) * column_us + y, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1}, tag});
    }
  }
}

TEST(BackgroundActivity, CorrelatedEdgeEventsPassIsolatedEventsDrop) {
  FilterConfig config;
  config.background_window_us = 2000;
  config.background_min_noise_hz = 0;
  FilterChain filter = only("background-activity", config);
  std::vector<Tagged> events;
  add_sweeping_edge(events, 10'000, 500, /*tag=*/0);
  // Isolated events: pixels far apart, each alone in its neighbourhood for far longer than the window.
  for (int i = 0; i < 200; ++i) {
    events.push_back(
        {{200'000 + 10'000 * i, static_cast<std::uint16_t>((i * 7) % 64), static_cast<std::uint16_t>((i * 5) % 48), -1},
         1});
  }
  const auto counts = passed_by_tag(filter, events);
  EXPECT_GE(counts.at(0).first, counts.at(0).second - 1);  // all but the very first event of the edge
  EXPECT_EQ(counts.at(1).first, 0);
  EXPECT_EQ(filter.counts().background_activity,
            static_cast<std::uint64_t>(counts.at(0).second - counts.at(0).first + 200));
}

/// Isolated events at `hz` per pixel over the whole sensor, each alone in its neighbourhood.
void add_uncorrelated(std::vector<Tagged>& events, double hz, Timestamp from, Timestamp to, int tag) {
  const auto spacing = static_cast<Timestamp>(1e6 / (hz * kSensor.width * kSensor.height));
  int i = 0;
  for (Timestamp t = from; t < to; t += spacing, ++i) {
    events.push_back(
        {{t, static_cast<std::uint16_t>((i * 37) % 64), static_cast<std::uint16_t>((i * 23) % 48), 1}, tag});
  }
}

TEST(BackgroundActivity, DropsUncorrelatedEventsOnlyWhileTheSensorIsNoisy) {
  FilterConfig config;
  config.background_window_us = 2000;
  config.background_min_noise_hz = 1.0;
  FilterChain filter = only("background-activity", config);
  std::vector<Tagged> events;
  add_uncorrelated(events, 0.3, 0, 1'000'000, /*tag=*/0);          // a clean sensor's sparse events: kept
  add_uncorrelated(events, 5.0, 1'000'000, 1'200'000, /*tag=*/1);  // noise begins: judged over 200 ms
  add_uncorrelated(events, 5.0, 1'200'000, 2'000'000, /*tag=*/2);  // then dropped
  const auto counts = passed_by_tag(filter, events);
  EXPECT_EQ(counts.at(0).first, counts.at(0).second);
  EXPECT_LE(counts.at(2).first, counts.at(2).second / 50);
}

TEST(Refractory, APixelFiresAtMostOncePerPeriod) {
  FilterConfig config;
  config.refractory_us = 100;
  FilterChain filter = only("refractory", config);
  std::vector<Tagged> events;
  for (int i = 0; i < 10; ++i) events.push_back({{1000 + 50 * i, 3, 4, 1}, i % 2});  // even ones are 100 us apart
  events.push_back({{1010, 5, 4, 1}, 0});                                            // another pixel, unaffected
  const auto counts = passed_by_tag(filter, events, 3);
  EXPECT_EQ(counts.at(0), std::make_pair(6, 6));
  EXPECT_EQ(counts.at(1), std::make_pair(0, 5));
}

TEST(HotPixel, MaskedWithinItsLearningTimeAndReleasedWhenItCools) {
  FilterChain filter = only("hot-pixel");  // windows of 200 ms, hot above 200 Hz and 8x its neighbours
  std::vector<Tagged> events;
  // The hot pixel fires at 2 kHz for 1 s, then at 20 Hz (cooled) for 1 s.
  for (Timestamp t = 0; t < 1'000'000; t += 500) events.push_back({{t, 10, 10, 1}, t < 400'000 ? 0 : 1});
  for (Timestamp t = 1'000'000; t < 2'000'000; t += 50'000) events.push_back({{t, 10, 10, 1}, t < 1'400'000 ? 2 : 3});
  // Edges sweep over the sensor, the hot pixel's neighbours included, every 250 ms.
  for (Timestamp t0 = 5'000; t0 < 2'000'000; t0 += 250'000) add_sweeping_edge(events, t0, 200, /*tag=*/4);
  for (Tagged& e : events) {
    if (e.tag == 4 && e.event.x == 10 && e.event.y == 10) e.tag = 5;  // the edge at the masked pixel itself
  }
  const auto counts = passed_by_tag(filter, events);
  // Learning takes until the end of the window in which it is first seen hot: at most 2 windows.
  EXPECT_EQ(counts.at(1).first, 0) << "hot events after 400 ms passed";
  EXPECT_LE(counts.at(0).first, 400'000 / 500);
  EXPECT_EQ(counts.at(3).first, counts.at(3).second) << "the cooled pixel was not released after 400 ms";
  EXPECT_EQ(counts.at(4).first, counts.at(4).second) << "edge events around the hot pixel dropped";
  EXPECT_TRUE(filter.masked_pixels().empty());
}

TEST(HotPixel, AMaskedPixelIsListedWhileHot) {
  FilterChain filter = only("hot-pixel");
  EventBatch batch;
  for (Timestamp t = 0; t < 500'000; t += 400) batch.push_back(t, 63, 47, -1);  // a corner pixel: 3 neighbours
  EventBatch passed;
  filter.filter(batch, passed);
  EXPECT_LT(passed.size(), batch.size());
  ASSERT_EQ(filter.masked_pixels().size(), 1u);
  EXPECT_EQ(filter.masked_pixels()[0], 47u * 64 + 63);
}

/// A 100 Hz light over a patch: each period an ON burst of 3 events at phase 0 and an OFF burst at
/// phase 5 ms, at every pixel of the patch.
void add_flicker(std::vector<Tagged>& events, Timestamp from, Timestamp to, double hz, int tag) {
  const auto period = static_cast<Timestamp>(1e6 / hz);
  for (Timestamp t = from; t < to; t += period) {
    for (int x = 20; x < 30; ++x) {
      for (int y = 10; y < 20; ++y) {
        for (int k = 0; k < 3; ++k) {
          events.push_back({{t + 20 * k + y, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1}, tag});
          events.push_back(
              {{t + period / 2 + 20 * k + y, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), -1}, tag});
        }
      }
    }
  }
}

TEST(AntiFlicker, A100HzBurstTrainIsRemovedWhileAnEdgeUnderItIsKept) {
  FilterChain filter = only("anti-flicker");
  std::vector<Tagged> events;
  add_flicker(events, 0, 50'000, 100, /*tag=*/0);          // locking on: 3 periods
  add_flicker(events, 50'000, 1'000'000, 100, /*tag=*/1);  // locked
  // Edges cross the patch (and the rest of the sensor) between the bursts, four times a second.
  for (Timestamp t0 = 102'500; t0 < 1'000'000; t0 += 250'000) add_sweeping_edge(events, t0, 20, /*tag=*/2, 18, 32);
  const auto counts = passed_by_tag(filter, events);
  EXPECT_LE(counts.at(1).first, counts.at(1).second / 100)
      << "flicker passed: " << counts.at(1).first << " of " << counts.at(1).second;
  EXPECT_EQ(counts.at(2).first, counts.at(2).second) << "edge events dropped";
}

TEST(AntiFlicker, FlickerOutsideTheBandAndIrregularEventsPass) {
  FilterChain filter = only("anti-flicker");  // 50-520 Hz
  std::vector<Tagged> events;
  add_flicker(events, 0, 1'000'000, 20, /*tag=*/0);  // 20 Hz: below the band
  // A pixel firing at irregular intervals in the band's range.
  Timestamp t = 0;
  for (int i = 0; i < 200; ++i) {
    t += 2000 + (i * 7919) % 15000;
    events.push_back({{t, 40, 40, 1}, 1});
  }
  const auto counts = passed_by_tag(filter, events);
  EXPECT_EQ(counts.at(0).first, counts.at(0).second);
  EXPECT_EQ(counts.at(1).first, counts.at(1).second);
}

TEST(FilterChain, RunsInOrderAndCountsEachReason) {
  FilterConfig config;
  config.chain = parse_filter_chain("refractory,background-activity");
  config.background_min_noise_hz = 0;  // always on
  FilterChain chain(config, kSensor);
  EventBatch batch;
  batch.push_back(100, 5, 5, 1);
  batch.push_back(120, 5, 5, 1);    // refractory: 20 us after the previous at this pixel
  batch.push_back(150, 6, 5, 1);    // correlated with (5, 5)
  batch.push_back(900, 40, 40, 1);  // isolated
  EventBatch passed;
  chain.filter(batch, passed);
  EXPECT_EQ(batch.size(), 4u);  // the input is left as it was
  ASSERT_EQ(passed.size(), 1u);
  EXPECT_EQ(passed[0], (Event{150, 6, 5, 1}));
  const FilterCounts counts = chain.counts();
  EXPECT_EQ(counts.events_in, 4u);
  EXPECT_EQ(counts.passed, 1u);
  EXPECT_EQ(counts.refractory, 1u);
  EXPECT_EQ(counts.background_activity, 2u);  // (5, 5) had no neighbour yet, and the isolated one
  EXPECT_EQ(counts.hot_pixel, 0u);

  EXPECT_TRUE(parse_filter_chain("none").empty());
  EXPECT_EQ(format_filter_chain(parse_filter_chain("anti-flicker,hot-pixel")), "anti-flicker,hot-pixel");
  EXPECT_THROW(parse_filter_chain("hot-pixel,median"), std::invalid_argument);
  EXPECT_THROW(parse_filter_chain("hot-pixel,hot-pixel"), std::invalid_argument);
  EXPECT_THROW(parse_filter_chain("hot-pixel,"), std::invalid_argument);
  config.background_window_us = 0;
  EXPECT_THROW(FilterChain(config, kSensor), std::invalid_argument);
  config.background_window_us = 5000;
  config.chain = {"refractory", "hot-pixel", "refractory"};  // a repeated filter: refused
  EXPECT_THROW(FilterChain(config, kSensor), std::invalid_argument);
  config.chain = {"refractory"};
  config.refractory_us = 1'000'000'001;  // above 1000 s: refused (the filter keeps 32-bit times)
  EXPECT_THROW(FilterChain(config, kSensor), std::invalid_argument);
}

}  // namespace
}  // namespace evldt
