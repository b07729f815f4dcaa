#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "evldt/events/event_validator.hpp"

namespace evldt {
namespace {

TEST(EventValidator, DropsOffSensorAndBackwardsEventsAndKeepsOrder) {
  EventValidator validator({10, 8}, /*backwards_slack_us=*/5);
  EventBatch batch;
  batch.push_back(100, 1, 1, 1);
  batch.push_back(101, 10, 1, 1);  // x == width: off
  batch.push_back(102, 2, 8, -1);  // y == height: off
  batch.push_back(96, 3, 3, -1);   // 5 us back: within slack
  batch.push_back(94, 4, 4, 1);    // 6 us back: dropped
  batch.push_back(110, 9, 7, 1);
  EXPECT_EQ(validator.filter(batch), 3u);
  ASSERT_EQ(batch.size(), 3u);
  EXPECT_EQ(batch[0], (Event{100, 1, 1, 1}));
  EXPECT_EQ(batch[1], (Event{96, 3, 3, -1}));
  EXPECT_EQ(batch[2], (Event{110, 9, 7, 1}));
  EXPECT_EQ(validator.drops().off_sensor, 2u);
  EXPECT_EQ(validator.drops().time_backwards, 1u);
  EXPECT_EQ(validator.accepted(), 3u);
  EXPECT_EQ(validator.newest_time(), 110);

  // The newest time carries over batches.
  EventBatch next;
  next.push_back(100, 0, 0, 1);
  EXPECT_EQ(validator.filter(next), 1u);
  EXPECT_TRUE(next.empty());
}

TEST(EventValidator, OneEventFarInTheFutureCostsAtMostARunNotTheStream) {
  EventValidator validator({10, 8}, /*backwards_slack_us=*/5);
  EventBatch batch;
  batch.push_back(1000, 1, 1, 1);
  batch.push_back(1000 + 3'600'000'000LL, 2, 2, 1);  // a corrupt timestamp, an hour ahead
  const auto stream_events = static_cast<Timestamp>(2 * kClockResetRun);
  for (Timestamp i = 0; i < stream_events; ++i) batch.push_back(1001 + i, 3, 3, -1);
  validator.filter(batch);
  // The first kClockResetRun - 1 stream events are dropped; then the validator follows the stream again.
  EXPECT_EQ(validator.drops().time_backwards, kClockResetRun - 1);
  EXPECT_EQ(validator.drops().clock_resets, 1u);
  EXPECT_EQ(batch.size(), 2 + static_cast<std::size_t>(stream_events) - (kClockResetRun - 1));
  EXPECT_EQ(validator.newest_time(), 1000 + stream_events);
}

TEST(EventValidator, ShortBackwardsRunsNeverResetTheClock) {
  EventValidator validator({10, 8}, 0);
  EventBatch batch;
  for (int round = 0; round < 5; ++round) {
    batch.push_back(10'000 * (round + 1), 1, 1, 1);
    for (std::uint64_t i = 0; i + 2 < kClockResetRun; ++i) batch.push_back(5, 2, 2, 1);
  }
  validator.filter(batch);
  EXPECT_EQ(validator.drops().clock_resets, 0u);
  EXPECT_EQ(batch.size(), 5u);
}

// The rules event by event, as EventValidator applied them before its block fast path: the
// reference the fast path must match in every kept event and every count.
struct ReferenceValidator {
  ReferenceValidator(SensorSize sensor_size, Timestamp slack_us) : sensor(sensor_size), slack(slack_us) {}

  SensorSize sensor;
  Timestamp slack;
  Timestamp newest = std::numeric_limits<Timestamp>::min();
  std::uint64_t accepted = 0;
  std::uint64_t backwards_run = 0;
  DropCounts drops;

  std::size_t filter(EventBatch& batch) {
    std::size_t kept = 0;
    const std::size_t n = batch.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Timestamp t = batch.t[i];
      if (!sensor.contains(batch.x[i], batch.y[i])) {
        ++drops.off_sensor;
        continue;
      }
      if (newest != std::numeric_limits<Timestamp>::min() && t < newest - slack) {
        if (++backwards_run < kClockResetRun) {
          ++drops.time_backwards;
          continue;
        }
        ++drops.clock_resets;
        newest = t;
      }
      backwards_run = 0;
      if (t > newest) newest = t;
      batch.t[kept] = t;
      batch.x[kept] = batch.x[i];
      batch.y[kept] = batch.y[i];
      batch.p[kept] = batch.p[i];
      ++kept;
    }
    batch.truncate(kept);
    accepted += kept;
    return n - kept;
  }
};

std::vector<Event> events_of(const EventBatch& batch) {
  std::vector<Event> events;
  for (std::size_t i = 0; i < batch.size(); ++i) events.push_back(batch[i]);
  return events;
}

// Batches of up to a few thousand events (across the fast path's blocks), in time order but for
// rare faults of every kind: off the sensor in x or y, a step back within or beyond the slack, a
// jump far ahead (a clock reset follows), equal times, a batch that starts behind the last.
EventBatch faulty_batch(std::mt19937_64& random, Timestamp& t, SensorSize sensor, double fault_rate) {
  std::uniform_int_distribution<std::size_t> size(0, 3000);
  std::uniform_real_distribution<double> unit(0, 1);
  std::uniform_int_distribution<int> kind(0, 6);
  const auto coordinate = [&](int side) {
    return static_cast<std::uint16_t>(std::uniform_int_distribution<int>(0, std::max(side, 1) - 1)(random));
  };
  EventBatch batch;
  const std::size_t n = size(random);
  for (std::size_t i = 0; i < n; ++i) {
    t += std::uniform_int_distribution<Timestamp>(0, 3)(random);
    std::uint16_t x = coordinate(sensor.width), y = coordinate(sensor.height);
    Timestamp event_t = t;
    if (unit(random) < fault_rate) {
      switch (kind(random)) {
        case 0:
          x = static_cast<std::uint16_t>(std::max(sensor.width, 0) + coordinate(3));
          break;
        case 1:
          y = 65535;
          break;
        case 2:
          event_t = t - std::uniform_int_distribution<Timestamp>(0, 8)(random);
          break;  // around the slack
        case 3:
          event_t = t - 1000;
          break;
        case 4:
          t += 100'000;
          break;  // the clock jumps: the next kClockResetRun events fall behind it
        case 5:
          t -= 100'000;
          event_t = t;
          break;  // the clock goes back
        default:
          break;
      }
    }
    batch.push_back(event_t, x, y, unit(random) < 0.5 ? std::int8_t{1} : std::int8_t{-1});
  }
  return batch;
}

TEST(EventValidator, FastPathKeepsExactlyWhatTheEventByEventRulesKeep) {
  std::mt19937_64 random(20251202);
  const std::vector<SensorSize> sensors{{1280, 720}, {10, 8}, {1, 1}, {0, 5}, {4096, 4096}, {70000, 70000}};
  for (const SensorSize sensor : sensors) {
    for (const Timestamp slack : {Timestamp{0}, Timestamp{5}, Timestamp{-3}}) {
      for (const double fault_rate : {0.0, 0.0005, 0.02, 0.5}) {
        SCOPED_TRACE(testing::Message() << sensor.width << "x" << sensor.height << " slack " << slack << " faults "
                                        << fault_rate);
        EventValidator validator(sensor, slack);
        ReferenceValidator reference(sensor, slack);
        Timestamp t = 1'000'000;
        for (int round = 0; round < 12; ++round) {
          EventBatch batch = faulty_batch(random, t, sensor, fault_rate);
          EventBatch expected = batch;
          ASSERT_EQ(validator.filter(batch), reference.filter(expected)) << "round " << round;
          ASSERT_EQ(events_of(batch), events_of(expected)) << "round " << round;
          ASSERT_EQ(batch.x.size(), batch.size());
          ASSERT_EQ(batch.p.size(), batch.size());
          ASSERT_EQ(validator.newest_time(), reference.newest);
          ASSERT_EQ(validator.accepted(), reference.accepted);
          ASSERT_EQ(validator.drops().off_sensor, reference.drops.off_sensor);
          ASSERT_EQ(validator.drops().time_backwards, reference.drops.time_backwards);
          ASSERT_EQ(validator.drops().clock_resets, reference.drops.clock_resets);
        }
      }
    }
  }
}

TEST(EventValidator, BlocksThatPassWholeStillFollowTheNewestTimeAndTheSlack) {
  // 600 events in order (a full fast block and part of the next), then a block that starts within
  // the slack behind the newest (kept whole), then one that starts beyond it (its first is dropped).
  EventValidator validator({10, 8}, 5);
  EventBatch batch;
  for (Timestamp i = 0; i < 600; ++i) batch.push_back(1000 + i, 1, 1, 1);
  EXPECT_EQ(validator.filter(batch), 0u);
  EXPECT_EQ(validator.newest_time(), 1599);
  EventBatch within;
  for (Timestamp i = 0; i < 600; ++i) within.push_back(1594 + i / 100, 2, 2, -1);
  EXPECT_EQ(validator.filter(within), 0u);
  EXPECT_EQ(validator.newest_time(), 1599);
  EventBatch beyond;
  beyond.push_back(1593, 3, 3, 1);
  for (Timestamp i = 0; i < 600; ++i) beyond.push_back(1600 + i, 3, 3, 1);
  EXPECT_EQ(validator.filter(beyond), 1u);
  ASSERT_EQ(beyond.size(), 600u);
  EXPECT_EQ(beyond.t.front(), 1600);
  EXPECT_EQ(validator.newest_time(), 2199);
  EXPECT_EQ(validator.drops().time_backwards, 1u);
  EXPECT_EQ(validator.accepted(), 1800u);
}

}  // namespace
}  // namespace evldt
