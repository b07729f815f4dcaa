#include <gtest/gtest.h>

#include "evldt/events/event_validator.hpp"

namespace evldt {
namespace {

TEST(EventValidator, DropsOffSensorAndBackwardsEventsAndKeepsOrder) {
  EventValidator validator({10, 8}, /*backwards_slack_us=*/5);
  EventBatch batch;
  batch.push_back(100, 1, 1, 1);
  batch.push_back(101, 10, 1, 1);   // x == width: off
  batch.push_back(102, 2, 8, -1);   // y == height: off
  batch.push_back(96, 3, 3, -1);    // 5 us back: within slack
  batch.push_back(94, 4, 4, 1);     // 6 us back: dropped
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

}  // namespace
}  // namespace evldt
