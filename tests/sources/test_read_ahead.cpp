#include <gtest/gtest.h>

#include <thread>

#include "evldt/events/event_format.hpp"
#include "evldt/sources/read_ahead.hpp"

namespace evldt {
namespace {

// Batch k holds k + 1 events at time 1000 k; after `batches` of them the source ends, or throws.
class CountingSource final : public EventSource {
 public:
  CountingSource(int batches, bool throws) : batches_(batches), throws_(throws) { name_ = "counting"; }
  bool read(EventBatch& batch) override {
    batch.clear();
    if (read_ == batches_) {
      if (throws_) throw FormatError("counting", 123, "cut");
      return false;
    }
    for (int i = 0; i <= read_; ++i) batch.push_back(1000 * read_, static_cast<std::uint16_t>(i), 0, 1);
    ++read_;
    return true;
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return SensorSize{240, 180}; }
  [[nodiscard]] double progress() const override { return static_cast<double>(read_) / batches_; }

 private:
  int batches_;
  bool throws_;
  int read_ = 0;
};

// A prepare step that keeps the events at even x, slowly now and then, so the reader and the
// consumer each get ahead of the other at times.
void keep_even(EventBatch& batch, EventBatch& prepared) {
  prepared.clear();
  for (std::size_t i = 0; i < batch.size(); ++i) {
    if (batch.x[i] % 2 == 0) prepared.push_back(batch[i]);
  }
  if (batch.size() % 7 == 0) std::this_thread::sleep_for(std::chrono::microseconds(300));
}

TEST(ReadAhead, HandsOutEveryBatchInOrderWithWhatPrepareMadeOfIt) {
  for (const std::size_t depth : {std::size_t{2}, std::size_t{3}, std::size_t{8}}) {
    CountingSource source(50, false);
    ReadAhead reader(source, keep_even, depth);
    int k = 0;
    while (const ReadAhead::Item* item = reader.next()) {
      ASSERT_EQ(item->batch.size(), static_cast<std::size_t>(k + 1)) << depth;
      EXPECT_EQ(item->events_read, static_cast<std::uint64_t>(k + 1));
      EXPECT_EQ(item->batch.t.front(), 1000 * k);
      EXPECT_EQ(item->prepared.size(), static_cast<std::size_t>(k / 2 + 1));
      EXPECT_DOUBLE_EQ(item->progress, (k + 1) / 50.0);
      if (k % 5 == 0) std::this_thread::sleep_for(std::chrono::microseconds(300));
      ++k;
    }
    EXPECT_EQ(k, 50) << depth;
    EXPECT_EQ(reader.next(), nullptr);  // and stays ended
  }
}

TEST(ReadAhead, WhatTheSourceThrowsComesAfterTheBatchesBeforeIt) {
  CountingSource source(10, true);
  ReadAhead reader(source, keep_even);
  int k = 0;
  try {
    while (reader.next() != nullptr) ++k;
    FAIL() << "the source's error was lost";
  } catch (const FormatError& error) {
    EXPECT_EQ(error.byte_offset(), 123u);
  }
  EXPECT_EQ(k, 10);
  EXPECT_EQ(reader.next(), nullptr);
}

TEST(ReadAhead, StopsWhenTheConsumerStopsEarly) {
  CountingSource source(1000, false);
  {
    ReadAhead reader(source, keep_even);
    ASSERT_NE(reader.next(), nullptr);
  }  // destroyed with batches unread: joins without reading the rest
  EXPECT_LT(source.progress(), 0.1);
  EXPECT_THROW(ReadAhead(source, keep_even, 1), std::invalid_argument);
}

}  // namespace
}  // namespace evldt
