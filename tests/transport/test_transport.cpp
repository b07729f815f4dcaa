// The transport layer on its own: checked decoding of every message type, event batching, loss and
// latency accounting, the receiving end of an event channel, pacing and reading lcm-logger files.

#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <random>
#include <thread>

#include "evldt/client/line_subscriber.hpp"
#include "evldt/transport/channels.hpp"
#include "evldt/transport/event_batch_receiver.hpp"
#include "evldt/transport/event_batcher.hpp"
#include "evldt/transport/latency_budget.hpp"
#include "evldt/transport/latency_tracker.hpp"
#include "evldt/transport/lcm_log.hpp"
#include "evldt/transport/lcm_log_reader.hpp"
#include "evldt/transport/messages.hpp"
#include "evldt/transport/pacer.hpp"
#include "evldt/transport/payload_queue.hpp"
#include "evldt/transport/sensor_lag.hpp"
#include "evldt/transport/sequence_tracker.hpp"
#include "support/lcm_log_writing.hpp"

namespace evldt {
namespace {

using Bytes = std::vector<std::uint8_t>;

template <typename Message>
Bytes encode(const Message& msg) {
  Bytes bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

EventBatch make_events(std::size_t n, Timestamp t0 = 1000, Timestamp step = 3) {
  EventBatch events;
  for (std::size_t i = 0; i < n; ++i) {
    events.push_back(t0 + static_cast<Timestamp>(i) * step, static_cast<std::uint16_t>(i % 240),
                     static_cast<std::uint16_t>(i % 180), i % 3 ? std::int8_t{1} : std::int8_t{-1});
  }
  return events;
}

// The typed message lcm-gen's code would send for these events: the reference the direct wire
// encoding must match, and a message tests can corrupt field by field before encoding it.
event_batch_t make_batch(const EventBatch& events, std::int64_t seq, std::int64_t epoch = 7, int width = 240,
                         int height = 180) {
  event_batch_t msg;
  msg.utime = 123;
  msg.epoch = epoch;
  msg.seq = seq;
  msg.source = "cam0";
  msg.width = static_cast<std::int16_t>(width);
  msg.height = static_cast<std::int16_t>(height);
  msg.t_base_us = events.empty() ? 0 : events.t.front();
  msg.num_events = static_cast<std::int32_t>(events.size());
  for (std::size_t i = 0; i < events.size(); ++i) {
    msg.dt_us.push_back(static_cast<std::int32_t>(events.t[i] - msg.t_base_us));
    msg.x.push_back(static_cast<std::int16_t>(events.x[i]));
    msg.y.push_back(static_cast<std::int16_t>(events.y[i]));
    msg.polarity.push_back(events.p[i] > 0 ? 1 : 0);
  }
  return msg;
}

segment_list_t make_list() {
  TrackedLine a;
  a.id = 42;
  a.segment = Segment{Point2(1.5, 2.5), Point2(30.25, 40.75)};
  a.score = 0.8F;
  a.status = LineStatus::GoodTrack;
  a.admin_block = 17;
  a.first_seen_us = 100;
  a.last_good_us = 900;
  a.normal_velocity = -123.5F;
  a.normal_velocity_std = 7.25F;
  TrackedLine b = a;
  b.id = 43;
  b.status = LineStatus::BadTrack;
  segment_list_t msg;
  msg.utime = 5;
  msg.epoch = 6;
  msg.seq = 7;
  msg.source = "cam0";
  msg.width = 240;
  msg.height = 180;
  msg.t_us = 1000;
  msg.newest_batch_seq = 3;
  msg.newest_batch_utime = 4;
  const std::vector<TrackedLine> lines{a, b};
  fill_segment_list(lines, msg);
  return msg;
}

stats_t make_stats() {
  stats_t msg{};
  msg.service = "evldt-lines";
  msg.source = "cam0";
  msg.events_in = 99;
  msg.filters = "hot-pixel,background-activity";
  msg.filtered_hot_pixel = 7;
  msg.sensor_lag_samples = 12;
  msg.sensor_lag_p99_ms = 4.5F;
  msg.masked_pixels = {5, 640 * 3 + 9};
  msg.num_masked_pixels = 2;
  return msg;
}

// ---- checked decoding ----------------------------------------------------------------------------

TEST(Messages, EventBatchWireEncodingIsLcmGensAndDecodesBackToEveryEvent) {
  const EventBatch events = make_events(500);
  const event_batch_t msg = make_batch(events, 3);
  std::vector<std::uint8_t> direct;
  encode_event_batch(msg, events, direct);
  const Bytes reference = encode(msg);
  EXPECT_EQ(direct, reference);  // byte for byte what lcm-gen's encoder writes
  EXPECT_EQ(direct.size(), 8 + 3 * 8 + 4 + 5 + 2 * 2 + 8 + 4 + 500 * kEventWireBytes);

  event_batch_t header;
  EventBatch back;
  ASSERT_EQ(decode_event_batch(reference, header, back), WireError::None);
  EXPECT_EQ(header.seq, 3);
  EXPECT_EQ(header.epoch, 7);
  EXPECT_EQ(header.utime, 123);
  EXPECT_EQ(header.source, "cam0");
  EXPECT_EQ(header.width, 240);
  EXPECT_EQ(header.num_events, 500);
  ASSERT_EQ(back.size(), events.size());
  for (std::size_t i = 0; i < events.size(); ++i) EXPECT_EQ(back[i], events[i]) << i;
}

TEST(Messages, EmptyEventBatchRoundTrips) {
  const EventBatch none;
  std::vector<std::uint8_t> bytes;
  encode_event_batch(make_batch(none, 0), none, bytes);
  EXPECT_EQ(bytes, encode(make_batch(none, 0)));
  event_batch_t header;
  EventBatch back = make_events(3);
  EXPECT_EQ(decode_event_batch(bytes, header, back), WireError::None);
  EXPECT_TRUE(back.empty());
}

TEST(Messages, SegmentListRoundTripKeepsEveryField) {
  const segment_list_t msg = make_list();
  segment_list_t decoded;
  ASSERT_EQ(decode_message(encode(msg), decoded), WireError::None);
  std::vector<TrackedLine> lines;
  ASSERT_TRUE(read_segment_list(decoded, lines));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].id, 42u);
  EXPECT_FLOAT_EQ(lines[0].segment.q1.x(), 30.25F);
  EXPECT_FLOAT_EQ(lines[0].segment.q1.y(), 40.75F);
  EXPECT_EQ(lines[0].status, LineStatus::GoodTrack);
  EXPECT_EQ(lines[1].status, LineStatus::BadTrack);
  EXPECT_EQ(lines[0].admin_block, 17);
  EXPECT_EQ(lines[0].last_good_us, 900);
  EXPECT_FLOAT_EQ(lines[0].normal_velocity, -123.5F);
  EXPECT_FLOAT_EQ(lines[0].normal_velocity_std, 7.25F);
}

TEST(Messages, ASegmentWithoutAFiniteVelocityOrWithANegativeDeviationIsRefused) {
  for (const auto& [velocity, deviation] :
       {std::pair(std::numeric_limits<float>::quiet_NaN(), 1.0f),
        std::pair(std::numeric_limits<float>::infinity(), 1.0f), std::pair(5.0f, -1.0f)}) {
    segment_list_t msg = make_list();
    msg.segments[1].normal_velocity = velocity;
    msg.segments[1].normal_velocity_std = deviation;
    std::vector<TrackedLine> lines;
    EXPECT_FALSE(read_segment_list(msg, lines));
    EXPECT_TRUE(lines.empty());
  }
}

// A segment list as evldt encoded it before line_segment_t carried the velocity (bytes written by
// that build's lcm-gen types): its fingerprint is another type's. Every consumer counts it as
// invalid; none crashes. An older consumer refuses today's lists the same way (LCM checks the
// fingerprint before any field).
TEST(Messages, ASegmentListOfTheTypeBeforeMotionIsRefusedAsAnotherType) {
  std::ifstream in(std::string(EVLDT_SOURCE_DIR) + "/tests/data/lcm/segment_list_before_motion.bin", std::ios::binary);
  ASSERT_TRUE(in);
  const Bytes old_bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(old_bytes.size(), 8u);
  segment_list_t decoded;
  EXPECT_EQ(decode_message(old_bytes, decoded), WireError::WrongType);
  // The generated decoder alone (what a plain LCM consumer calls) refuses it too.
  EXPECT_LT(decoded.decode(old_bytes.data(), 0, static_cast<int>(old_bytes.size())), 0);
  // The consumer SDK counts it as undecodable.
  lcm::LCM bus("memq://");
  ASSERT_TRUE(bus.good());
  int lists = 0;
  client::LineSubscriber subscriber(bus, "cam0", [&](const client::LineList&) { ++lists; });
  bus.publish("LINES_CAM0", old_bytes.data(), static_cast<unsigned>(old_bytes.size()));
  bus.publish("WHOLE_LINES_CAM0", old_bytes.data(), static_cast<unsigned>(old_bytes.size()));
  for (int k = 0; k < 3; ++k) bus.handleTimeout(50);
  EXPECT_EQ(lists, 0);
  EXPECT_EQ(subscriber.undecodable(), 2u);
}

TEST(Messages, StatsRoundTrip) {
  stats_t decoded;
  ASSERT_EQ(decode_message(encode(make_stats()), decoded), WireError::None);
  EXPECT_EQ(decoded.events_in, 99);
  EXPECT_EQ(decoded.service, "evldt-lines");
  EXPECT_EQ(decoded.filters, "hot-pixel,background-activity");
  EXPECT_EQ(decoded.filtered_hot_pixel, 7);
  EXPECT_EQ(decoded.sensor_lag_samples, 12);
  EXPECT_FLOAT_EQ(decoded.sensor_lag_p99_ms, 4.5F);
  EXPECT_EQ(decoded.masked_pixels, (std::vector<std::int32_t>{5, 640 * 3 + 9}));
}

// Every strict prefix of a valid message, and the message with a byte appended, must be refused.
template <typename Message>
void expect_every_prefix_malformed(const Bytes& bytes) {
  Message out;
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const WireError error = decode_message(std::span(bytes.data(), n), out);
    ASSERT_EQ(error, WireError::Malformed) << "prefix of " << n << " of " << bytes.size() << " bytes";
  }
  Bytes longer = bytes;
  longer.push_back(0);
  EXPECT_EQ(decode_message(longer, out), WireError::Malformed);
}

TEST(Messages, EveryTruncationIsMalformed) {
  Bytes batch = encode(make_batch(make_events(20), 1));
  event_batch_t header;
  EventBatch events;
  for (std::size_t n = 0; n < batch.size(); ++n) {
    ASSERT_EQ(decode_event_batch(std::span(batch.data(), n), header, events), WireError::Malformed) << n;
    ASSERT_TRUE(events.empty());
  }
  batch.push_back(0);
  EXPECT_EQ(decode_event_batch(batch, header, events), WireError::Malformed);
  expect_every_prefix_malformed<segment_list_t>(encode(make_list()));
  expect_every_prefix_malformed<stats_t>(encode(make_stats()));
}

camera_info_t make_camera_info() {
  RectificationTable table;
  table.sensor = {240, 180};
  table.lens = {199.1, 198.8, 132.2, 110.7, "radtan", {-0.37, 0.15, -0.0003, -0.0008, 0.0}, "calib.yaml"};
  camera_info_t msg{};
  msg.utime = 5;
  msg.epoch = 6;
  msg.source = "cam0";
  fill_camera_info(table, msg);
  return msg;
}

TEST(Messages, CameraInfoRoundTrip) {
  camera_info_t decoded;
  ASSERT_EQ(decode_message(encode(make_camera_info()), decoded), WireError::None);
  EXPECT_EQ(decoded.width, 240);
  EXPECT_EQ(decoded.height, 180);
  EXPECT_DOUBLE_EQ(decoded.fx, 199.1);
  EXPECT_DOUBLE_EQ(decoded.cx, 132.2);
  EXPECT_EQ(decoded.sensor_distortion, "radtan");
  EXPECT_EQ(decoded.calibration, "calib.yaml");
  EXPECT_EQ(decoded.coefficients.size(), 5u);
  expect_every_prefix_malformed<camera_info_t>(encode(make_camera_info()));
  stats_t stats;
  EXPECT_EQ(decode_message(encode(make_camera_info()), stats), WireError::WrongType);
}

TEST(Messages, AnotherTypeIsWrongTypeNotMalformed) {
  event_batch_t batch;
  EventBatch events;
  segment_list_t list;
  stats_t stats;
  EXPECT_EQ(decode_event_batch(encode(make_list()), batch, events), WireError::WrongType);
  EXPECT_EQ(decode_message(encode(make_batch(make_events(3), 0)), list), WireError::WrongType);
  EXPECT_EQ(decode_message(encode(make_list()), stats), WireError::WrongType);
}

// Offset of num_events in an encoded event batch with the source "cam0".
constexpr std::size_t kNumEventsOffset = 8 + 3 * 8 + 4 + 5 + 2 * 2 + 8;

TEST(Messages, ForgedCountIsRefusedBeforeAllocating) {
  Bytes bytes = encode(make_batch(make_events(4), 0));
  // Claim 2^31-1 events in a message carrying four: lcm-gen's decoder would size the arrays first.
  bytes[kNumEventsOffset] = 0x7F;
  bytes[kNumEventsOffset + 1] = bytes[kNumEventsOffset + 2] = bytes[kNumEventsOffset + 3] = 0xFF;
  event_batch_t out;
  EventBatch events;
  EXPECT_EQ(decode_event_batch(bytes, out, events), WireError::Malformed);
  bytes[kNumEventsOffset] = 0x80;  // negative
  EXPECT_EQ(decode_event_batch(bytes, out, events), WireError::Malformed);
}

TEST(Messages, UnterminatedOrOverlongStringIsMalformed) {
  Bytes bytes = encode(make_batch(make_events(2), 0));
  const std::size_t string_end = 8 + 3 * 8 + 4 + 4;  // the NUL after "cam0"
  bytes[string_end] = 'x';
  event_batch_t out;
  EventBatch events;
  EXPECT_EQ(decode_event_batch(bytes, out, events), WireError::Malformed);
  Bytes overlong = encode(make_batch(make_events(2), 0));
  overlong[8 + 3 * 8] = 0x7F;  // string length far beyond the message
  EXPECT_EQ(decode_event_batch(overlong, out, events), WireError::Malformed);
}

TEST(Messages, StringWithANulBeforeItsEndIsMalformed) {
  // Found by fuzz_segment_list_message: lcm-gen decodes "ca\0m" but encodes it back as "ca".
  Bytes bytes = encode(make_batch(make_events(2), 0));
  bytes[8 + 3 * 8 + 4 + 2] = 0;  // "cam0" -> "ca\00"
  event_batch_t out;
  EventBatch events;
  EXPECT_EQ(decode_event_batch(bytes, out, events), WireError::Malformed);
  segment_list_t list = make_list();
  list.source = "cam0";
  Bytes list_bytes = encode(list);
  list_bytes[8 + 3 * 8 + 4 + 1] = 0;
  EXPECT_EQ(decode_message(list_bytes, list), WireError::Malformed);
}

TEST(Messages, SegmentListWithUnknownStatusOrNanIsRefused) {
  segment_list_t msg = make_list();
  std::vector<TrackedLine> lines;
  msg.segments[1].status = 3;
  EXPECT_FALSE(read_segment_list(msg, lines));
  EXPECT_TRUE(lines.empty());
  msg = make_list();
  msg.segments[0].x1 = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(read_segment_list(msg, lines));
}

TEST(Messages, NegativeCoordinatesBecomeOffSensorAndBadTimeBaseIsRefused) {
  event_batch_t msg = make_batch(make_events(2), 0);
  msg.x[0] = -5;
  event_batch_t header;
  EventBatch out;
  ASSERT_EQ(decode_event_batch(encode(msg), header, out), WireError::None);
  EXPECT_FALSE((SensorSize{240, 180}.contains(out.x[0], out.y[0])));
  msg.t_base_us = -1;
  EXPECT_EQ(decode_event_batch(encode(msg), header, out), WireError::Malformed);
  EXPECT_TRUE(out.empty());
  msg.t_base_us = (std::int64_t{1} << 62) + 1;
  EXPECT_EQ(decode_event_batch(encode(msg), header, out), WireError::Malformed);
}

TEST(Messages, BatchSpanBeyondInt32IsRejectedOnEncode) {
  EventBatch events;
  events.push_back(0, 1, 1, 1);
  events.push_back(kMaxBatchSpanUs + 1, 1, 1, 1);
  std::vector<std::uint8_t> bytes;
  EXPECT_THROW(encode_event_batch(event_batch_t{}, events, bytes), std::invalid_argument);
}

TEST(Messages, BatchSpanUpToInt32EitherWayIsEncodedAsLcmGenDoes) {
  for (const Timestamp base : {Timestamp{0}, Timestamp{5'000'000'000}, Timestamp{-7}}) {
    EventBatch events;
    events.push_back(base, 1, 2, 1);
    events.push_back(base + kMaxBatchSpanUs, 3, 4, -1);
    events.push_back(base - kMaxBatchSpanUs, 65535, 0, 1);  // out of order: encoded all the same
    for (std::size_t i = 0; i < 37; ++i)
      events.push_back(base + static_cast<Timestamp>(i) * 70000, static_cast<std::uint16_t>(i * 1000), 719, -1);
    std::vector<std::uint8_t> bytes{1, 2, 3};
    encode_event_batch(make_batch(events, 1), events, bytes);
    EXPECT_EQ(bytes, encode(make_batch(events, 1))) << base;
    for (const Timestamp beyond : {base + kMaxBatchSpanUs + 1, base - kMaxBatchSpanUs - 1, base + (Timestamp{1} << 32),
                                   base + (Timestamp{1} << 32) + 5, base - (Timestamp{1} << 32)}) {
      EventBatch bad = events;
      bad.push_back(beyond, 1, 1, 1);
      std::vector<std::uint8_t> untouched = bytes;
      EXPECT_THROW(encode_event_batch(event_batch_t{}, bad, untouched), std::invalid_argument) << beyond - base;
      EXPECT_EQ(untouched, bytes);  // nothing written before the refusal
    }
  }
}

// ---- channels -----------------------------------------------------------------------------------

TEST(Channels, NamesAreUpperCaseAndCameraNamesChecked) {
  EXPECT_EQ(events_channel("front_1"), "EVENTS_FRONT_1");
  EXPECT_EQ(lines_channel("cam0"), "LINES_CAM0");
  EXPECT_NO_THROW(check_camera_name("cam_0"));
  EXPECT_THROW(check_camera_name(""), std::invalid_argument);
  EXPECT_THROW(check_camera_name("a.b"), std::invalid_argument);
  EXPECT_THROW(check_camera_name(std::string(33, 'a')), std::invalid_argument);
}

// ---- batching -----------------------------------------------------------------------------------

TEST(EventBatcher, CutsAtAlignedWindowsAndMaxSize) {
  EventBatcher batcher(1000, 4);
  EventBatch in;
  for (Timestamp t : {10, 20, 30, 990, 1000, 1500, 2999, 3000}) in.push_back(t, 1, 1, 1);
  in.push_back(3001, 1, 1, 1);
  batcher.push(in);
  EventBatch out;
  std::vector<std::vector<Timestamp>> batches;
  while (batcher.pop(out)) batches.push_back(out.t);
  // [10,20,30,990] fills max_events; [1000,1500] ends at the window; [2999]; [3000,3001] incomplete.
  const std::vector<std::vector<Timestamp>> expected{{10, 20, 30, 990}, {1000, 1500}, {2999}};
  EXPECT_EQ(batches, expected);
  EXPECT_EQ(batcher.pending(), 2u);
  ASSERT_TRUE(batcher.pop(out, /*flush=*/true));
  EXPECT_EQ(out.t, (std::vector<Timestamp>{3000, 3001}));
  EXPECT_FALSE(batcher.pop(out, true));
}

TEST(EventBatcher, KeepsEveryEventInOrderAcrossManyPushes) {
  EventBatcher batcher(250, 100);
  std::vector<Timestamp> popped;
  EventBatch out;
  for (int chunk = 0; chunk < 50; ++chunk) {
    batcher.push(make_events(37, 1000 + chunk * 37 * 5, 5));
    while (batcher.pop(out)) {
      ASSERT_LE(out.size(), 100u);
      popped.insert(popped.end(), out.t.begin(), out.t.end());
    }
  }
  while (batcher.pop(out, true)) popped.insert(popped.end(), out.t.begin(), out.t.end());
  ASSERT_EQ(popped.size(), 50u * 37u);
  for (std::size_t i = 0; i < popped.size(); ++i) ASSERT_EQ(popped[i], 1000 + static_cast<Timestamp>(i) * 5);
}

// EventBatcher as it was with one buffer (append on push, copy on pop, the consumed prefix erased):
// the reference for its batches.
class ReferenceBatcher {
 public:
  ReferenceBatcher(Timestamp window_us, std::size_t max_events) : window_us_(window_us), max_events_(max_events) {}
  void push(const EventBatch& events) {
    if (head_ > 0 && head_ * 2 >= buffer_.size()) {
      EventBatch rest;
      rest.append(buffer_, head_, buffer_.size());
      buffer_ = rest;
      head_ = 0;
    }
    buffer_.append(events, 0, events.size());
  }
  bool pop(EventBatch& out, bool flush) {
    out.clear();
    if (pending() == 0) return false;
    const Timestamp first = buffer_.t[head_];
    const Timestamp index = first >= 0 ? first / window_us_ : -((-first - 1) / window_us_) - 1;
    const Timestamp end_t = (index + 1) * window_us_;
    std::size_t end = head_;
    while (end < buffer_.size() && end - head_ < max_events_ && buffer_.t[end] < end_t) ++end;
    const bool complete = end < buffer_.size() || end - head_ == max_events_;
    if (!complete && !flush) return false;
    out.append(buffer_, head_, end);
    head_ = end;
    return true;
  }
  [[nodiscard]] std::size_t pending() const { return buffer_.size() - head_; }

 private:
  Timestamp window_us_;
  std::size_t max_events_;
  EventBatch buffer_;
  std::size_t head_ = 0;
};

std::vector<Event> events_of(const EventBatch& batch) {
  std::vector<Event> events;
  for (std::size_t i = 0; i < batch.size(); ++i) events.push_back(batch[i]);
  return events;
}

TEST(EventBatcher, BatchesAsTheSingleBufferBatcherDidAcrossWindowAndSizeBoundaries) {
  std::mt19937_64 random(20251202);
  std::uniform_int_distribution<int> percent(0, 99);
  for (const Timestamp window : {Timestamp{1}, Timestamp{7}, Timestamp{1000}}) {
    for (const std::size_t max_events : {std::size_t{1}, std::size_t{3}, std::size_t{64}, std::size_t{7000}}) {
      SCOPED_TRACE(testing::Message() << "window " << window << " max " << max_events);
      EventBatcher batcher(window, max_events);
      ReferenceBatcher reference(window, max_events);
      Timestamp t = -5000;  // windows before 0 too
      EventBatch chunk, out, expected;
      std::size_t popped = 0;
      for (int round = 0; round < 300; ++round) {
        // Chunks of 0 to 2000 events, times in order but for steps back within a few us (the
        // validator's slack lets those through), some pushed by copy, some handed over.
        chunk.clear();
        const std::size_t n = std::uniform_int_distribution<std::size_t>(0, percent(random) < 10 ? 2000 : 40)(random);
        for (std::size_t i = 0; i < n; ++i) {
          t += std::uniform_int_distribution<Timestamp>(0, window * 3)(random);
          const Timestamp jitter = percent(random) < 5 ? std::uniform_int_distribution<Timestamp>(0, 3)(random) : 0;
          chunk.push_back(t - jitter, static_cast<std::uint16_t>(i), static_cast<std::uint16_t>(round),
                          i % 2 ? std::int8_t{1} : std::int8_t{-1});
        }
        reference.push(chunk);
        if (percent(random) < 50) {
          batcher.push(chunk);
        } else {
          batcher.push(std::move(chunk));
          EXPECT_TRUE(chunk.empty());
        }
        ASSERT_EQ(batcher.pending(), reference.pending());
        // Pop some or all of the complete batches, now and then flushing the tail too.
        const bool flush = percent(random) < 5;
        const int pops = percent(random) < 70 ? 1000000 : percent(random) % 4;
        for (int p = 0; p < pops; ++p) {
          const bool got = batcher.pop(out, flush);
          ASSERT_EQ(got, reference.pop(expected, flush)) << "round " << round << " pop " << p;
          ASSERT_EQ(events_of(out), events_of(expected)) << "round " << round << " pop " << p;
          ASSERT_EQ(batcher.pending(), reference.pending());
          if (!got) break;
          popped += out.size();
        }
      }
      while (batcher.pop(out, true)) {
        ASSERT_TRUE(reference.pop(expected, true));
        ASSERT_EQ(events_of(out), events_of(expected));
        popped += out.size();
      }
      EXPECT_FALSE(reference.pop(expected, true));
      EXPECT_EQ(batcher.pending(), 0u);
      EXPECT_GT(popped, 0u);
    }
  }
}

TEST(EventBatcher, HandedOverChunksComeBackEmptyWithTheStorageOfConsumedOnes) {
  EventBatcher batcher(1000, 7000);
  EventBatch chunk = make_events(5000, 0, 1);  // 0..4999 us: windows 0..4 complete once 5000 arrives
  batcher.push(std::move(chunk));
  EXPECT_TRUE(chunk.empty());
  EXPECT_EQ(batcher.pending(), 5000u);
  chunk = make_events(10, 5000, 1);
  batcher.push(std::move(chunk));
  EventBatch out;
  std::size_t popped = 0;
  while (batcher.pop(out)) popped += out.size();
  EXPECT_EQ(popped, 5000u);
  EXPECT_EQ(batcher.pending(), 10u);
  chunk = make_events(3, 6000, 1);
  batcher.push(std::move(chunk));
  EXPECT_TRUE(chunk.empty());
  EXPECT_GE(chunk.t.capacity(), 5000u);  // the first chunk's columns, ready to be filled again
  ASSERT_TRUE(batcher.pop(out));
  EXPECT_EQ(out.t, make_events(10, 5000, 1).t);
  ASSERT_TRUE(batcher.pop(out, true));
  EXPECT_EQ(out.t, make_events(3, 6000, 1).t);
}

TEST(EventBatcher, RefusesZeroWindowOrSize) {
  EXPECT_THROW(EventBatcher(0, 10), std::invalid_argument);
  EXPECT_THROW(EventBatcher(10, 0), std::invalid_argument);
}

// ---- sequence and latency accounting -----------------------------------------------------------

TEST(SequenceTracker, CountsGapsLateAndRestarts) {
  SequenceTracker tracker;
  EXPECT_TRUE(tracker.observe(1, 0));
  EXPECT_TRUE(tracker.observe(1, 1));
  EXPECT_TRUE(tracker.observe(1, 5));   // 2, 3, 4 lost
  EXPECT_FALSE(tracker.observe(1, 5));  // duplicate
  EXPECT_FALSE(tracker.observe(1, 3));  // reordered
  EXPECT_TRUE(tracker.observe(2, 0));   // restarted publisher
  EXPECT_FALSE(tracker.observe(1, 6));  // the old epoch
  EXPECT_TRUE(tracker.observe(2, 1));
  const SequenceCounts& counts = tracker.counts();
  EXPECT_EQ(counts.received, 5u);
  EXPECT_EQ(counts.lost, 3u);
  EXPECT_EQ(counts.late, 3u);
  EXPECT_EQ(counts.restarts, 1u);
}

TEST(SequenceTracker, OneForgedMessageAheadCannotSilenceTheStream) {
  SequenceTracker tracker;
  EXPECT_TRUE(tracker.observe(1, 0));
  EXPECT_TRUE(tracker.observe(INT64_MAX, INT64_MAX));  // forged: the newest epoch there can be
  std::int64_t seq = 1;
  for (; seq < static_cast<std::int64_t>(kSequenceResyncRun); ++seq) EXPECT_FALSE(tracker.observe(1, seq));
  EXPECT_TRUE(tracker.observe(1, seq));  // the real camera's stream is followed again
  EXPECT_TRUE(tracker.observe(1, seq + 1));
  const SequenceCounts& counts = tracker.counts();
  EXPECT_EQ(counts.late, kSequenceResyncRun - 1);
  EXPECT_EQ(counts.resyncs, 1u);
  EXPECT_EQ(counts.restarts, 2u);  // the forged epoch, then the resync
  EXPECT_EQ(counts.lost, 0u);
}

TEST(SequenceTracker, TwoPublishersInterleavedFollowTheNewerWithoutResync) {
  SequenceTracker tracker;
  for (std::int64_t seq = 0; seq < 300; ++seq) {
    tracker.observe(1, seq);  // a camera started earlier with the same name
    EXPECT_TRUE(tracker.observe(2, seq));
  }
  EXPECT_EQ(tracker.counts().resyncs, 0u);
  EXPECT_EQ(tracker.counts().late, 299u);
}

TEST(SequenceTracker, ForgedHugeSequenceDoesNotOverflow) {
  SequenceTracker tracker;
  EXPECT_TRUE(tracker.observe(1, INT64_MIN));
  EXPECT_TRUE(tracker.observe(1, INT64_MAX));
  EXPECT_FALSE(tracker.observe(1, INT64_MAX));
  EXPECT_EQ(tracker.counts().lost, UINT64_MAX - 1);
}

TEST(LatencyTracker, MeasuresFromPublishToTheListThatIncludesTheBatch) {
  LatencyTracker tracker(4, 100);
  tracker.batch_stored(0, 1000, 1100, 100);  // received 0.1 ms after its publish
  tracker.batch_stored(1, 2000, 2100, 200);
  tracker.batch_stored(2, 3000, 3100, 300);
  auto included = tracker.list_published(150, 5000);  // only batch 0: 4 ms
  EXPECT_EQ(included.seq, 0);
  EXPECT_EQ(included.utime, 1000);
  included = tracker.list_published(150, 6000);  // nothing new
  EXPECT_EQ(included.seq, 0);
  included = tracker.list_published(300, 7000);  // batches 1 and 2: 5 ms and 4 ms
  EXPECT_EQ(included.seq, 2);
  const LatencySummary period = tracker.take_summary();
  EXPECT_EQ(period.samples, 3u);
  EXPECT_DOUBLE_EQ(period.median_ms, 4.0);
  EXPECT_DOUBLE_EQ(period.p99_ms, 5.0);
  EXPECT_EQ(tracker.take_summary().samples, 0u);
  const LatencySummary run = tracker.run_summary();  // bins of 0.1 ms, upper edges
  EXPECT_EQ(run.samples, 3u);
  EXPECT_NEAR(run.median_ms, 4.1, 1e-9);
  EXPECT_NEAR(run.p99_ms, 5.1, 1e-9);
}

TEST(LatencyTracker, ForgetsTheOldestBeyondCapacity) {
  LatencyTracker tracker(2, 100);
  for (std::int64_t seq = 0; seq < 5; ++seq) tracker.batch_stored(seq, seq * 1000, seq * 1000 + 100, seq * 10);
  tracker.list_published(1000, 10000);
  EXPECT_EQ(tracker.take_summary().samples, 2u);  // batches 3 and 4 only
}

TEST(LatencyTracker, SettledFiguresLeaveOutTheStreamsFirstSecond) {
  LatencyTracker tracker(64, 100);
  // A slow start: the first second's batches wait 30 ms for their list, the later ones 2 ms.
  for (std::int64_t k = 0; k < 20; ++k) {
    const std::int64_t publish = k * 100'000;  // 0.1 s apart
    tracker.batch_stored(k, publish, publish + 100, k * 100);
    tracker.list_published(k * 100, publish + (publish < LatencyTracker::kSettleUs ? 30'000 : 2'000));
  }
  const LatencySummary run = tracker.run_summary();
  const LatencySummary settled = tracker.settled_summary();
  EXPECT_EQ(run.samples, 20u);
  EXPECT_NEAR(run.p99_ms, 30.1, 1e-9);
  EXPECT_EQ(settled.samples, 10u);  // published 1.0 s .. 1.9 s after the first
  EXPECT_NEAR(settled.median_ms, 2.1, 1e-9);
  EXPECT_NEAR(settled.p99_ms, 2.1, 1e-9);
}

// A replayed log keeps the recording's publish stamps, here a second behind this host's clock; a
// camera host's clock may be set apart either way. Measured from the stamps, every batch would read
// as a second late: the latency is measured from receipt instead, and the offset is known. Clocks
// within kClocksApartUs measure from the publish, their transit included.
TEST(LatencyTracker, PublishStampsFarFromOurClockAreMeasuredFromReceipt) {
  for (const std::int64_t behind : {std::int64_t{1'000'000}, std::int64_t{-600'000}, std::int64_t{30'000}}) {
    SCOPED_TRACE(behind);
    LatencyTracker tracker(64, 100);
    for (std::int64_t k = 0; k < 50; ++k) {
      const std::int64_t publish = 5'000'000 + k * 10'000;
      const std::int64_t received = publish + behind + 200 + (k % 3) * 100;  // 0.2-0.4 ms transit
      tracker.batch_stored(k, publish, received, k * 10'000);
      tracker.list_published(k * 10'000, received + 2'000);  // each in a list 2 ms after it came
    }
    const bool apart = behind > LatencyTracker::kClocksApartUs;
    ASSERT_TRUE(tracker.publish_clock_offset_us().has_value());
    EXPECT_EQ(*tracker.publish_clock_offset_us(), behind + 200);
    EXPECT_EQ(tracker.measured_from_receipt(), apart || behind < 0 ? 50u : 0u);
    const LatencySummary run = tracker.run_summary();
    EXPECT_EQ(run.samples, 50u);
    if (apart || behind < 0) {
      EXPECT_NEAR(run.median_ms, 2.05, 0.06);  // 2 ms, in bins of 0.1 ms
    } else {
      EXPECT_NEAR(run.median_ms, 32.35, 0.06);  // 32.3 ms: the 30 ms apart and the transit count
    }
  }
}

// ---- receiving end -----------------------------------------------------------------------------

TEST(EventBatchReceiver, AdoptsSensorCountsLossAndRefusesForeignPayloads) {
  EventBatchReceiver receiver(std::nullopt, 0);
  EventBatch out;
  ASSERT_TRUE(receiver.receive(encode(make_batch(make_events(10, 0), 0)), out));
  EXPECT_EQ(out.size(), 10u);
  EXPECT_EQ(receiver.sensor(), (SensorSize{240, 180}));

  const Bytes junk{1, 2, 3, 4, 5};
  EXPECT_FALSE(receiver.receive(junk, out));
  EXPECT_FALSE(receiver.receive(encode(make_list()), out));
  EXPECT_FALSE(receiver.receive(encode(make_batch(make_events(3, 100), 1, 7, 346, 260)), out));  // other sensor
  EXPECT_FALSE(receiver.receive(encode(make_batch(make_events(3, 100), 1, 7, 0, 180)), out));    // no sensor

  // Seq 3 after 0: two lost; one event off the sensor dropped.
  event_batch_t msg = make_batch(make_events(5, 100), 3);
  msg.x[2] = 240;
  ASSERT_TRUE(receiver.receive(encode(msg), out));
  EXPECT_EQ(out.size(), 4u);

  const ReceiverCounts counts = receiver.counts();
  EXPECT_EQ(counts.invalid_messages, 4u);
  EXPECT_EQ(counts.sequence.received, 2u);
  EXPECT_EQ(counts.sequence.lost, 2u);
  EXPECT_EQ(counts.drops.off_sensor, 1u);
}

TEST(SensorLag, MeasuresEachBatchBeyondTheQuickestAndTheClocksOffset) {
  SensorLag lag;
  // A sensor whose clock started 1000 s before the wall clock's epoch: every batch is published
  // 2 ms after its newest event, every tenth one 12 ms after (held up on the way).
  constexpr std::int64_t kOffsetUs = 1'000'000'000;
  for (int i = 0; i < 1000; ++i) {
    const Timestamp t = i * 1000;
    lag.published(t, t + kOffsetUs + 2000 + (i % 10 == 9 ? 10'000 : 0));
  }
  EXPECT_NEAR(lag.clock_offset_s(), 1000.002, 1e-9);
  const LatencySummary period = lag.take_summary();
  EXPECT_EQ(period.samples, 1000u);
  EXPECT_DOUBLE_EQ(period.median_ms, 0.0);
  EXPECT_DOUBLE_EQ(period.p99_ms, 10.0);
  EXPECT_EQ(lag.take_summary().samples, 0u);  // a period's samples are taken once
  EXPECT_EQ(lag.run_summary().samples, 1000u);
  // The camera restarts: its clock begins at 0 again. Learnt afresh, the lag is not 1000 s.
  lag.restart();
  lag.published(500, 1'000'000'000'000 + 500 + 3000);
  EXPECT_DOUBLE_EQ(lag.take_summary().p99_ms, 0.0);
  EXPECT_NEAR(lag.clock_offset_s(), 1'000'000.003, 1e-9);
}

TEST(LatencyBudget, ThinsWhatQueuedAndShedsWhatQueuedPastTheBudgetWhateverTheSendersClock) {
  for (const std::int64_t offset : {std::int64_t{0}, std::int64_t{5'000'000}, std::int64_t{-3'000'000}}) {
    LatencyBudget budget(20);  // ms
    // Delivered in 0.3-0.5 ms; the sender's clock is `offset` behind ours.
    std::int64_t now = 10'000'000;
    for (int i = 0; i < 100; ++i, now += 1000)
      EXPECT_EQ(budget.stride(now - offset - 300 - (i % 3) * 100, now), 1) << offset;
    EXPECT_EQ(budget.stride(now - offset - 300 - 19'900, now), 1);  // queued 19.9 ms: all of it kept
    EXPECT_EQ(budget.stride(now - offset - 300 - 20'100, now), 2);  // past the budget: every 2nd
    EXPECT_EQ(budget.stride(now - offset - 300 - 30'100, now), 4);  // past 1.5 budgets: every 4th
    EXPECT_EQ(budget.stride(now - offset - 300 - 39'900, now), 4);
    EXPECT_EQ(budget.stride(now - offset - 300 - 41'000, now), 0);  // past twice: shed whole
    EXPECT_NEAR(static_cast<double>(budget.last_queueing_us()), 41'000, 1);
  }
  LatencyBudget shed_only(20, 2'000'000, OverloadPolicy::Shed);
  std::int64_t now = 10'000'000;
  EXPECT_EQ(shed_only.stride(now - 300, now), 1);
  EXPECT_EQ(shed_only.stride(now - 300 - 19'000, now), 1);
  EXPECT_EQ(shed_only.stride(now - 300 - 21'000, now), 0);
  LatencyBudget never(0);
  EXPECT_EQ(never.stride(0, 10'000'000), 1);
  EXPECT_EQ(never.stride(1'000'000, 10'000'000), 1);
  EXPECT_THROW(LatencyBudget(-1), std::invalid_argument);
}

TEST(LatencyBudget, WhatQueuedWhileTheConsumerStartedIsNotLate) {
  LatencyBudget budget(20);
  std::int64_t now = 1'000'000;
  const std::int64_t offset = 2'000'000;                 // the sender's clock is ahead of ours
  EXPECT_EQ(budget.stride(now + offset - 400, now), 1);  // the first batch: the consumer starts on it
  // It takes 60 ms to start; 60 batches published meanwhile (one a millisecond) arrive together.
  now += 60'000;
  budget.ready_at(now);
  for (std::int64_t k = 1; k <= 60; ++k) EXPECT_EQ(budget.stride(now + offset - 60'000 - 400 + k * 1000, now), 1) << k;
  EXPECT_NEAR(static_cast<double>(budget.last_queueing_us()), 0, 1);  // the last of them queued briefly
  // After the start a stall is judged as ever.
  now += 60'000;
  EXPECT_EQ(budget.stride(now + offset - 400 - 25'000, now), 2);
  EXPECT_EQ(budget.stride(now + offset - 400 - 45'000, now), 0);
  EXPECT_EQ(budget.stride(now + offset - 400, now), 1);
}

TEST(LatencyBudget, AClockStepIsForgottenWithinTwoWindows) {
  LatencyBudget budget(20, /*window_us=*/1'000'000);
  std::int64_t now = 0;
  for (; now < 3'000'000; now += 1000) budget.stride(now - 500, now);
  // The sender's clock steps 50 ms back: every batch now looks 50 ms old, then the estimate follows.
  bool thinned_late = false;
  for (; now < 6'000'000; now += 1000) {
    const int stride = budget.stride(now - 500 - 50'000, now);
    if (now >= 5'000'000) thinned_late = thinned_late || stride != 1;
  }
  EXPECT_FALSE(thinned_late);
}

TEST(EventBatchReceiver, ShedsLateBatchesUnreadButAccountsTheirSequence) {
  EventBatchReceiver receiver(std::nullopt, 0);
  LatencyBudget budget(20);
  EventBatch out;
  const std::int64_t now = 50'000'000;
  const auto batch_at = [](std::int64_t seq, std::int64_t utime, Timestamp t0) {
    event_batch_t msg = make_batch(make_events(10, t0), seq);
    msg.utime = utime;
    return encode(msg);
  };
  ASSERT_TRUE(receiver.receive(batch_at(0, now - 500, 0), out, budget, now));
  EXPECT_FALSE(receiver.shed());
  EXPECT_EQ(out.size(), 10u);
  // Seq 1 queued 45 ms, past twice the budget: shed, its events not decoded; its last event's time is kept.
  ASSERT_TRUE(receiver.receive(batch_at(1, now - 45'500, 100), out, budget, now));
  EXPECT_TRUE(receiver.shed());
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(receiver.shed_until_us(), 100 + 9 * 3);
  ASSERT_TRUE(receiver.receive(batch_at(2, now - 400, 200), out, budget, now));
  EXPECT_FALSE(receiver.shed());
  EXPECT_EQ(out.size(), 10u);
  // A shed batch is no loss, a late duplicate is not shed, junk is still refused.
  EXPECT_FALSE(receiver.receive(batch_at(1, now - 45'500, 100), out, budget, now));
  EXPECT_FALSE(receiver.receive(Bytes{1, 2, 3}, out, budget, now));
  const ReceiverCounts counts = receiver.counts();
  EXPECT_EQ(counts.sequence.received, 3u);
  EXPECT_EQ(counts.sequence.lost, 0u);
  EXPECT_EQ(counts.batches_shed, 1u);
  EXPECT_EQ(counts.events_shed, 10u);
  EXPECT_EQ(counts.invalid_messages, 1u);
}

TEST(EventBatchReceiver, ThinsBatchesThatQueuedEvenlyKeepingTheirLastEvent) {
  EventBatchReceiver receiver(std::nullopt, 0);
  LatencyBudget budget(20);
  EventBatch out;
  const std::int64_t now = 50'000'000;
  const auto batch_at = [](std::int64_t seq, std::int64_t utime, const EventBatch& events) {
    event_batch_t msg = make_batch(events, seq);
    msg.utime = utime;
    return encode(msg);
  };
  const EventBatch ten = make_events(10, 0);
  ASSERT_TRUE(receiver.receive(batch_at(0, now - 500, ten), out, budget, now));
  EXPECT_FALSE(receiver.thinned());
  EXPECT_EQ(receiver.stride(), 1);
  EXPECT_EQ(out.size(), 10u);
  // Queued 32 ms: every 4th event, ending with the last (events 1, 5 and 9 of its ten).
  const EventBatch later = make_events(10, 100);
  ASSERT_TRUE(receiver.receive(batch_at(1, now - 32'500, later), out, budget, now));
  EXPECT_TRUE(receiver.thinned());
  EXPECT_EQ(receiver.stride(), 4);  // what the subscriber stores each kept event as (RealtimeEngine::process)
  EXPECT_FALSE(receiver.shed());
  ASSERT_EQ(out.size(), 3u);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::size_t i = 9 - 4 * (out.size() - 1 - k);
    EXPECT_EQ(out.t[k], later.t[i]) << k;
    EXPECT_EQ(out.x[k], later.x[i]) << k;
    EXPECT_EQ(out.y[k], later.y[i]) << k;
    EXPECT_EQ(out.p[k], later.p[i]) << k;
  }
  // Then all of the next, that did not queue.
  ASSERT_TRUE(receiver.receive(batch_at(2, now - 400, make_events(10, 200)), out, budget, now));
  EXPECT_FALSE(receiver.thinned());
  EXPECT_EQ(receiver.stride(), 1);
  EXPECT_EQ(out.size(), 10u);
  const ReceiverCounts counts = receiver.counts();
  EXPECT_EQ(counts.sequence.received, 3u);
  EXPECT_EQ(counts.sequence.lost, 0u);
  EXPECT_EQ(counts.batches_shed, 0u);
  EXPECT_EQ(counts.batches_thinned, 1u);
  EXPECT_EQ(counts.events_shed, 7u);
}

TEST(EventBatchReceiver, RefusesSensorSizesBeyondTheLimitOrThatTheSubscriberCannotUse) {
  // The subscriber (as evldt-lines does) accepts only sizes its lattice fits.
  EventBatchReceiver receiver(std::nullopt, 0, [](SensorSize size) { return size.width >= 28 && size.height >= 28; });
  EventBatch out;
  EXPECT_FALSE(receiver.receive(encode(make_batch(make_events(3), 0, 7, 5000, 180)), out));  // beyond kMaxSensorSide
  EXPECT_FALSE(receiver.receive(encode(make_batch(make_events(3), 1, 7, -240, 180)), out));  // negative
  EXPECT_FALSE(receiver.receive(encode(make_batch(make_events(3), 2, 7, 20, 20)), out));     // too small to use
  EXPECT_FALSE(receiver.sensor().has_value());
  ASSERT_TRUE(receiver.receive(encode(make_batch(make_events(3), 3, 7, 240, 180)), out));
  EXPECT_EQ(receiver.sensor(), (SensorSize{240, 180}));
  EXPECT_EQ(receiver.counts().invalid_messages, 3u);
}

TEST(EventBatchReceiver, AClockThatWentBackRestartsTheSubscriber) {
  EventBatchReceiver receiver(SensorSize{240, 180}, 0);
  EventBatch out;
  ASSERT_TRUE(receiver.receive(encode(make_batch(make_events(10, 500'000), 0, 1)), out));
  // Same publisher epoch, time back by 0.5 s for more than kClockResetRun events.
  ASSERT_TRUE(receiver.receive(encode(make_batch(make_events(kClockResetRun + 10, 10, 1), 1, 1)), out));
  EXPECT_TRUE(receiver.restarted());
  EXPECT_EQ(out.size(), 11u);
  EXPECT_EQ(receiver.counts().drops.clock_resets, 1u);
  EXPECT_EQ(receiver.counts().drops.time_backwards, kClockResetRun - 1);
}

TEST(EventBatchReceiver, NewEpochRestartsTheTimeOrderCheck) {
  EventBatchReceiver receiver(SensorSize{240, 180}, 0);
  EventBatch out;
  ASSERT_TRUE(receiver.receive(encode(make_batch(make_events(10, 5000), 0, 1)), out));
  EXPECT_FALSE(receiver.restarted());
  // The same epoch going back in time: events dropped as time_backwards.
  ASSERT_TRUE(receiver.receive(encode(make_batch(make_events(4, 10), 1, 1)), out));
  EXPECT_TRUE(out.empty());
  // A restarted camera whose clock starts again: accepted.
  ASSERT_TRUE(receiver.receive(encode(make_batch(make_events(4, 10), 0, 2)), out));
  EXPECT_TRUE(receiver.restarted());
  EXPECT_EQ(out.size(), 4u);
  const ReceiverCounts counts = receiver.counts();
  EXPECT_EQ(counts.drops.time_backwards, 4u);
  EXPECT_EQ(counts.sequence.restarts, 1u);
}

// ---- pacing -------------------------------------------------------------------------------------

TEST(Pacer, UnlimitedSpeedNeverWaits) {
  Pacer pacer(0);
  std::atomic<bool> stop{false};
  const auto start = std::chrono::steady_clock::now();
  pacer.wait_until(0, stop);
  pacer.wait_until(3'600'000'000, stop);
  EXPECT_LT(std::chrono::steady_clock::now() - start,
            std::chrono::seconds(10));  // not the hour; room for a loaded machine
}

TEST(Pacer, AJumpOfEventTimeIsNotWaitedThrough) {
  Pacer pacer(1.0);
  std::atomic<bool> stop{false};
  std::thread stopper([&] {
    // Only if the pacer wrongly sleeps through the hour: end the test instead of hanging it.
    for (int i = 0; i < 100 && !stop; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    stop = true;
  });
  pacer.wait_until(1'000, stop);
  pacer.wait_until(3'600'000'000, stop);  // an hour later
  pacer.wait_until(500, stop);            // and back
  const bool stopped_early = stop.exchange(true);
  stopper.join();
  EXPECT_FALSE(stopped_early);
  EXPECT_EQ(pacer.skipped_gaps(), 2u);
}

TEST(Pacer, WaitsForEventTimeAndHonoursStop) {
  Pacer pacer(1.0);
  std::atomic<bool> stop{false};
  pacer.wait_until(0, stop);  // anchors
  const auto start = std::chrono::steady_clock::now();
  pacer.wait_until(30'000, stop);  // 30 ms later
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(29));
  stop = true;
  const auto stopped = std::chrono::steady_clock::now();
  pacer.wait_until(3'600'000'000, stop);  // an hour, but stop is set
  EXPECT_LT(std::chrono::steady_clock::now() - stopped, std::chrono::seconds(10));
}

// ---- lcm-logger files ---------------------------------------------------------------------------

class LcmLogFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("evldt_transport_" + std::to_string(::getpid()) + "_" +
                                                     ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Three batches of 100 events with junk and another camera interleaved, then two segment lists of
  // the same lattice time (the later one wins) and one of a later time.
  std::filesystem::path write_log() {
    const auto path = dir_ / "run.lcmlog";
    lcm::LogFile log(path.string(), "w");
    EXPECT_TRUE(log.good());
    for (std::int64_t seq = 0; seq < 3; ++seq) {
      test_support::write_log_event(log, seq, "EVENTS_CAM0",
                                    encode(make_batch(make_events(100, 1000 + seq * 1000, 10), seq)));
      test_support::write_log_event(log, seq, "EVENTS_CAM0", Bytes{9, 9, 9});
      test_support::write_log_event(log, seq, "EVENTS_CAM1", encode(make_batch(make_events(7, 0), seq)));
    }
    segment_list_t list = make_list();
    test_support::write_log_event(log, 10, "LINES_CAM0", encode(list));
    list.segments.pop_back();
    list.num_segments = 1;
    test_support::write_log_event(log, 11, "LINES_CAM0", encode(list));
    list.t_us = 2000;
    test_support::write_log_event(log, 12, "LINES_CAM0", encode(list));
    return path;
  }

  std::filesystem::path dir_;
};

TEST_F(LcmLogFiles, ReadsTheEventsOfOneCameraAndCountsJunk) {
  const auto path = write_log();
  EXPECT_TRUE(is_lcm_log(path));
  LcmLogEventReader reader(path, "", 0);
  EXPECT_EQ(reader.channel(), "EVENTS_CAM0");
  EXPECT_EQ(reader.sensor(), (SensorSize{240, 180}));
  EventBatch batch;
  std::vector<Timestamp> times;
  while (reader.read(batch)) times.insert(times.end(), batch.t.begin(), batch.t.end());
  ASSERT_EQ(times.size(), 300u);
  EXPECT_EQ(times.front(), 1000);
  EXPECT_EQ(times.back(), 3000 + 99 * 10);
  EXPECT_EQ(reader.counts().invalid_messages, 3u);
  EXPECT_EQ(reader.counts().sequence.lost, 0u);
  EXPECT_DOUBLE_EQ(reader.progress(), 1.0);
}

TEST_F(LcmLogFiles, ReadsSegmentListsOneStepPerLatticeTime) {
  const auto rows = read_segment_log(write_log());
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].t_us, 1000);
  EXPECT_EQ(rows[0].id, 42u);
  EXPECT_EQ(rows[1].t_us, 2000);
}

TEST_F(LcmLogFiles, TruncatedLogYieldsWhatPrecedesTheCut) {
  const auto path = write_log();
  // Cut inside the second batch message: the first batch survives.
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, 1200);
  ASSERT_LT(1200u, size);
  LcmLogEventReader reader(path, "EVENTS_CAM0", 0);
  EventBatch batch;
  std::size_t events = 0;
  while (reader.read(batch)) events += batch.size();
  EXPECT_EQ(events, 100u);
  EXPECT_THROW(read_segment_log(path), std::runtime_error);  // no list survived
}

TEST_F(LcmLogFiles, MissingOrForeignFilesAreClearErrors) {
  EXPECT_THROW(LcmLogEventReader(dir_ / "absent.lcmlog", "", 0), std::runtime_error);
  const auto text = dir_ / "events.txt";
  std::ofstream(text) << "0.000001 1 2 1\n";
  EXPECT_FALSE(is_lcm_log(text));
  const auto path = write_log();
  EXPECT_THROW(LcmLogEventReader(path, "EVENTS_NOPE", 0), std::runtime_error);
  EXPECT_THROW(read_segment_log(path, "LINES_NOPE"), std::runtime_error);
}

}  // namespace
}  // namespace evldt

namespace {
std::vector<std::uint8_t> bytes_of(std::size_t size, std::uint8_t fill) {
  return std::vector<std::uint8_t>(size, fill);
}
}  // namespace

TEST(PayloadQueue, HandsOverPayloadsInOrderAndGrowsASlotForALargeOne) {
  evldt::PayloadQueue queue(3, 16);
  const std::atomic<bool> never{false};
  ASSERT_TRUE(queue.push(bytes_of(5, 1), 100, never));
  ASSERT_TRUE(queue.push(bytes_of(40, 2), 200, never));  // larger than a slot: that slot grows
  ASSERT_TRUE(queue.push({}, 300, never));
  std::int64_t received = 100;
  for (const auto& [size, fill] : std::vector<std::pair<std::size_t, std::uint8_t>>{{5, 1}, {40, 2}, {0, 0}}) {
    const auto payload = queue.front(std::chrono::milliseconds(0));
    ASSERT_TRUE(payload.has_value());
    ASSERT_EQ(payload->bytes.size(), size);
    EXPECT_EQ(payload->received_utime, received);
    for (const std::uint8_t byte : payload->bytes) EXPECT_EQ(byte, fill);
    queue.pop();
    received += 100;
  }
  EXPECT_FALSE(queue.front(std::chrono::milliseconds(1)).has_value());
  EXPECT_EQ(queue.high_water(), 3u);
  // The slots go round: a fourth and fifth payload reuse the first two.
  ASSERT_TRUE(queue.push(bytes_of(7, 4), 400, never));
  ASSERT_TRUE(queue.push(bytes_of(30, 5), 500, never));
  EXPECT_EQ(queue.front(std::chrono::milliseconds(0))->bytes.size(), 7u);
  queue.pop();
  EXPECT_EQ(queue.front(std::chrono::milliseconds(0))->bytes[29], 5);
  EXPECT_EQ(queue.front(std::chrono::milliseconds(0))->received_utime, 500);
}

TEST(PayloadQueue, AFullQueueHoldsTheProducerUntilASlotFreesOrItStops) {
  evldt::PayloadQueue queue(1, 8);
  std::atomic<bool> stop{false};
  ASSERT_TRUE(queue.push(bytes_of(1, 1), 1, stop));
  std::atomic<bool> second_queued{false};
  std::thread producer([&] { second_queued = queue.push(bytes_of(2, 2), 2, stop); });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(second_queued.load());  // waits: nothing was dropped or overwritten
  EXPECT_EQ(queue.front(std::chrono::milliseconds(0))->bytes.size(), 1u);
  queue.pop();
  producer.join();
  EXPECT_TRUE(second_queued.load());
  EXPECT_EQ(queue.front(std::chrono::milliseconds(0))->bytes.size(), 2u);

  // Full again, and stopped meanwhile: the producer gives up.
  std::thread stopped_producer([&] { second_queued = queue.push(bytes_of(3, 3), 3, stop); });
  stop = true;
  stopped_producer.join();
  EXPECT_FALSE(second_queued.load());
  EXPECT_EQ(queue.front(std::chrono::milliseconds(0))->bytes.size(), 2u);
  EXPECT_THROW(evldt::PayloadQueue(0, 8), std::invalid_argument);
}

namespace evldt {
namespace {

// ---- lcm-logs read with every damage said ----------------------------------------------

/// A log of `count` records written by LCM's own LogFile, record k on channel "CH_k%3" with k + 40
/// bytes of k; returns where each record starts.
std::vector<std::uint64_t> write_lcm_log(const std::filesystem::path& path, int count) {
  std::vector<std::uint64_t> starts;
  lcm::LogFile log(path.string(), "w");
  for (int k = 0; k < count; ++k) {
    starts.push_back(static_cast<std::uint64_t>(std::ftell(log.getFilePtr())));
    std::vector<std::uint8_t> data(static_cast<std::size_t>(k + 40), static_cast<std::uint8_t>(k));
    lcm::LogEvent event{};
    event.eventnum = k;
    event.timestamp = 1'600'000'000'000'000 + k * 1000;
    event.channel = "CH_" + std::to_string(k % 3);
    event.datalen = static_cast<std::int32_t>(data.size());
    event.data = data.data();
    log.writeEvent(&event);
  }
  return starts;
}

struct ReadLog {
  std::vector<std::int64_t> numbers;
  LogDamage damage;
};

ReadLog read_log(const std::filesystem::path& path) {
  LcmLogReader reader(path);
  LcmLogReader::Record record;
  ReadLog result;
  while (reader.next(record)) {
    EXPECT_EQ(record.channel, "CH_" + std::to_string(record.number % 3));
    EXPECT_EQ(record.data, std::vector<std::uint8_t>(static_cast<std::size_t>(record.number + 40),
                                                     static_cast<std::uint8_t>(record.number)));
    EXPECT_EQ(record.t_us, 1'600'000'000'000'000 + record.number * 1000);
    result.numbers.push_back(record.number);
  }
  result.damage = reader.damage();
  return result;
}

void overwrite(const std::filesystem::path& path, std::uint64_t at, const std::string& bytes) {
  std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
  file.seekp(static_cast<std::streamoff>(at));
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::int64_t> numbers_but(int count, std::initializer_list<std::int64_t> lost) {
  std::vector<std::int64_t> numbers;
  for (std::int64_t k = 0; k < count; ++k) {
    if (std::find(lost.begin(), lost.end(), k) == lost.end()) numbers.push_back(k);
  }
  return numbers;
}

class LcmLogReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = std::filesystem::temp_directory_path() / ("evldt_log_" + std::to_string(::getpid()) + ".lcm");
    starts_ = write_lcm_log(path_, kRecords);
  }
  void TearDown() override { std::filesystem::remove(path_); }
  static constexpr int kRecords = 12;
  std::filesystem::path path_;
  std::vector<std::uint64_t> starts_;
};

TEST_F(LcmLogReaderTest, AWholeLogReadsEveryRecordAndNoDamage) {
  const ReadLog log = read_log(path_);
  EXPECT_EQ(log.numbers, numbers_but(kRecords, {}));
  EXPECT_FALSE(log.damage.any());
}

// 64 zeroed bytes over record 5's header: LCM's reader skipped them without a word.
TEST_F(LcmLogReaderTest, ZeroedBytesInTheMiddleAreSkippedCountedAndTheRestRead) {
  overwrite(path_, starts_[5] + 10, std::string(64, '\0'));
  const ReadLog log = read_log(path_);
  EXPECT_EQ(log.numbers, numbers_but(kRecords, {5}));
  EXPECT_EQ(log.damage.regions, 1u);
  EXPECT_EQ(log.damage.first_at, starts_[5]);
  EXPECT_EQ(log.damage.skipped_bytes, starts_[6] - starts_[5]);
  EXPECT_FALSE(log.damage.cut);
}

TEST_F(LcmLogReaderTest, ACutLastRecordIsSaidAndEveryWholeOneRead) {
  for (const std::uint64_t cut_after : {std::uint64_t{3}, std::uint64_t{20}, std::uint64_t{40}}) {
    SCOPED_TRACE(cut_after);
    write_lcm_log(path_, kRecords);
    std::filesystem::resize_file(path_, starts_[kRecords - 1] + cut_after);
    const ReadLog log = read_log(path_);
    EXPECT_EQ(log.numbers, numbers_but(kRecords - 1, {}));
    EXPECT_TRUE(log.damage.cut);
    EXPECT_EQ(log.damage.cut_at, starts_[kRecords - 1]);
    EXPECT_EQ(log.damage.regions, 0u);
  }
}

TEST_F(LcmLogReaderTest, ALengthDamagedToSwallowTheNextRecordsLosesOnlyItsOwn) {
  // Record 3's data length (the header's last four bytes) made 200 bytes longer: records 4 and on
  // start inside it, so its lengths are damaged.
  std::ifstream in(path_, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(starts_[3] + 24));
  unsigned char length[4];
  in.read(reinterpret_cast<char*>(length), 4);
  in.close();
  length[3] = static_cast<unsigned char>(length[3] + 200);
  overwrite(path_, starts_[3] + 24, std::string(reinterpret_cast<char*>(length), 4));
  const ReadLog log = read_log(path_);
  EXPECT_EQ(log.numbers, numbers_but(kRecords, {3}));
  EXPECT_EQ(log.damage.regions, 1u);
  EXPECT_EQ(log.damage.first_at, starts_[3]);
}

TEST_F(LcmLogReaderTest, GarbageBeforeTheFirstRecordAndAtTheEndIsCounted) {
  std::string bytes;
  {
    std::ifstream in(path_, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::ofstream(path_, std::ios::binary) << std::string(17, 'x') << bytes << std::string(2, 'y');
  const ReadLog log = read_log(path_);
  EXPECT_EQ(log.numbers, numbers_but(kRecords, {}));
  EXPECT_EQ(log.damage.regions, 2u);
  EXPECT_EQ(log.damage.skipped_bytes, 19u);
  EXPECT_EQ(log.damage.first_at, 0u);
}

TEST_F(LcmLogReaderTest, AnEmptyOrMissingFile) {
  std::ofstream(path_, std::ios::trunc).close();
  EXPECT_TRUE(read_log(path_).numbers.empty());
  EXPECT_FALSE(read_log(path_).damage.any());
  EXPECT_THROW(LcmLogReader(path_.string() + ".missing"), std::runtime_error);
}

}  // namespace
}  // namespace evldt

namespace evldt {
namespace {

// The consumer SDK over an in-process bus: a camera's segments and whole lines as plain structs;
// another type on its channels counted, not handed on.
TEST(LineSubscriber, HandsOverSegmentsAndWholeLinesAsPlainStructsAndCountsWhatDoesNotDecode) {
  lcm::LCM bus("memq://");
  ASSERT_TRUE(bus.good());
  std::vector<client::LineList> received;
  client::LineSubscriber subscriber(bus, "Cam0", [&](const client::LineList& list) { received.push_back(list); });
  segment_list_t list{};
  list.source = "cam0";
  list.width = 240;
  list.height = 180;
  list.t_us = 1'600'000'000'123'456;
  line_segment_t segment{};
  segment.id = 42;
  segment.x0 = 1.5f;
  segment.y0 = 2.5f;
  segment.x1 = 30.25f;
  segment.y1 = 40.75f;
  segment.score = 0.8f;
  segment.status = line_segment_t::STATUS_GOOD_TRACK;
  segment.normal_velocity = 55.5f;
  segment.normal_velocity_std = 3.0f;
  list.segments = {segment};
  list.num_segments = 1;
  bus.publish("LINES_CAM0", &list);
  list.segments.clear();
  list.num_segments = 0;
  bus.publish("WHOLE_LINES_CAM0", &list);
  const std::uint8_t junk[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  bus.publish("LINES_CAM0", junk, sizeof junk);
  bus.publish("LINES_CAM1", &list);  // another camera's
  for (int k = 0; k < 4; ++k) bus.handleTimeout(100);
  ASSERT_EQ(received.size(), 2u);
  EXPECT_FALSE(received[0].whole_lines);
  EXPECT_EQ(received[0].camera, "cam0");
  EXPECT_EQ(received[0].width, 240);
  EXPECT_EQ(received[0].t_us, 1'600'000'000'123'456);
  ASSERT_EQ(received[0].lines.size(), 1u);
  const client::Line& line = received[0].lines[0];
  EXPECT_EQ(line.id, 42);
  EXPECT_EQ(line.x0, 1.5f);
  EXPECT_EQ(line.y1, 40.75f);
  EXPECT_EQ(line.status, client::LineStatus::GoodTrack);
  EXPECT_EQ(line.normal_velocity, 55.5f);
  EXPECT_EQ(line.normal_velocity_std, 3.0f);
  EXPECT_TRUE(received[1].whole_lines);
  EXPECT_TRUE(received[1].lines.empty());
  EXPECT_EQ(subscriber.undecodable(), 1u);
}

}  // namespace
}  // namespace evldt
