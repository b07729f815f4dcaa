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

}  // namespace
}  // namespace evldt
