// Recording containers and the packet encodings, on fixtures written here from the format
// descriptions (ROS 2 bags in SQLite and MCAP files with event_camera_msgs/EventPacket and
// dvs_msgs/EventArray in CDR; ROS 1 bags written with rosbag_storage; AEDAT 4.0 with LZ4 /
// Zstandard packets), and on the real recordings in ../shared/real when they are there.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <lz4frame.h>
#include <rosbag/bag.h>
#include <sqlite3.h>
#include <zlib.h>
#include <zstd.h>

#include <bit>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "aedat4_header_generated.h"
#include "dv_events_generated.h"
#include "evldt/containers/aedat4.hpp"
#include "evldt/containers/image_source.hpp"
#include "evldt/containers/mcap.hpp"
#include "evldt/containers/packet_source.hpp"
#include "evldt/containers/ros_messages.hpp"
#include "evldt/containers/rosbag1.hpp"
#include "evldt/containers/rosbag2.hpp"
#include "evldt/events/event_writer.hpp"
#include "evldt/events/size_prefixed_flatbuffer.hpp"
#include "evldt/sources/event_source.hpp"
#include "support/raw_ros_message.hpp"
#include "support/ros2_bag_writer.hpp"
#include "support/temp_dir.hpp"

namespace evldt {
namespace {

using test_support::BagWriter;
using test_support::CdrWriter;
using test_support::TempDir;

std::vector<Event> events_of(const EventBatch& batch) {
  std::vector<Event> events;
  for (std::size_t i = 0; i < batch.size(); ++i) events.push_back(batch[i]);
  return events;
}

struct ReadAll {
  std::vector<Event> events;
  std::optional<SensorSize> sensor;
  std::string name;
  DecodeCounts counts;
  std::string error;
};

ReadAll read_all(const std::filesystem::path& path, const std::string& topic = {}) {
  ReadAll result;
  const auto source = open_recording(path, std::nullopt, topic, 1000);
  result.sensor = source->geometry();
  result.name = source->name();
  EventBatch batch;
  try {
    while (source->read(batch)) {
      const auto events = events_of(batch);
      result.events.insert(result.events.end(), events.begin(), events.end());
    }
  } catch (const FormatError& error) {
    result.error = error.what();
  }
  result.counts = source->decode_counts();
  return result;
}

// ---- CDR and ROS 2 bags --------------------------------------------------------------------------

struct PacketFields {
  std::string frame_id = "cam-7";
  std::uint32_t width = 640, height = 480;
  std::uint64_t seq = 0;
  std::uint64_t time_base = 0;
  std::string encoding = "evt3";
  std::vector<std::uint8_t> events;
};

std::vector<std::uint8_t> event_packet_cdr(const PacketFields& fields, bool little_endian = true) {
  CdrWriter cdr(little_endian);
  cdr.put<std::int32_t>(1700000000);
  cdr.put<std::uint32_t>(123);
  cdr.put_string(fields.frame_id);
  cdr.put(fields.height);
  cdr.put(fields.width);
  cdr.put(fields.seq);
  cdr.put(fields.time_base);
  cdr.put_string(fields.encoding);
  cdr.put<std::uint8_t>(0);
  cdr.put_bytes(fields.events);
  return cdr.bytes();
}

void append_le16(std::vector<std::uint8_t>& out, std::uint16_t word) {
  out.push_back(static_cast<std::uint8_t>(word));
  out.push_back(static_cast<std::uint8_t>(word >> 8));
}
void append_le32(std::vector<std::uint8_t>& out, std::uint32_t word) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(word >> (8 * i)));
}

EventBatch sweep_events(int count, Timestamp t0) {
  EventBatch events;
  for (int i = 0; i < count; ++i) {
    events.push_back(t0 + 3 * i, static_cast<std::uint16_t>((7 * i) % 640), static_cast<std::uint16_t>((5 * i) % 480),
                     i % 3 == 0 ? -1 : 1);
  }
  return events;
}

TEST(Cdr, EventPacketDecodesInEitherByteOrderAndRefusesTruncation) {
  PacketFields fields;
  fields.seq = 42;
  fields.time_base = 1234567890123ULL;
  fields.encoding = "libcaer";
  fields.events = {1, 2, 3, 4, 5};
  for (const bool little : {true, false}) {
    SCOPED_TRACE(little);
    const auto bytes = event_packet_cdr(fields, little);
    std::vector<std::uint8_t> scratch;
    const auto layout = RosEventLayout::of(RosSerialization::Cdr, kRos2EventPacketType, "");
    ASSERT_TRUE(layout);
    const RosEventMessage message = layout->decode(bytes, scratch);
    EXPECT_EQ(message.frame_id, "cam-7");
    EXPECT_EQ(message.width, 640u);
    EXPECT_EQ(message.height, 480u);
    EXPECT_EQ(message.time_base, 1234567890123ULL);
    EXPECT_EQ(message.encoding, "libcaer");
    EXPECT_EQ(std::vector<std::uint8_t>(message.events.begin(), message.events.end()), fields.events);
    for (std::size_t cut = 0; cut < bytes.size(); cut += 3) {
      EXPECT_THROW(layout->decode(std::span(bytes).first(cut), scratch), std::runtime_error) << cut;
    }
  }
}

TEST(Rosbag2, Evt3PacketsAreOneStreamSplitAnywhere) {
  TempDir dir;
  const auto path = dir.file("bag.db3");
  const EventBatch events = sweep_events(3000, 5'000'000);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(events, words);  // bare words: no header written
  {
    BagWriter bag(path);
    bag.topic(1, "/imu", "sensor_msgs/msg/Imu");
    bag.topic(2, "/event_camera/events", std::string(kRos2EventPacketType));
    bag.message(1, 10, {0, 1, 0, 0, 9, 9});
    // Packets cut at odd word counts: state (y, base x, time) carries from one packet to the next.
    PacketFields fields;
    for (std::size_t at = 0, seq = 0; at < words.size(); ++seq) {
      const std::size_t size = std::min<std::size_t>(words.size() - at, 2 * (37 + 101 * (seq % 5)));
      fields.seq = seq;
      fields.events.assign(words.begin() + static_cast<std::ptrdiff_t>(at),
                           words.begin() + static_cast<std::ptrdiff_t>(at + size));
      bag.message(2, 100 + static_cast<std::int64_t>(seq), event_packet_cdr(fields));
      at += size;
    }
  }
  const ReadAll result = read_all(path);
  EXPECT_EQ(result.error, "");
  EXPECT_EQ(result.events, events_of(events));
  EXPECT_EQ(result.sensor, (SensorSize{640, 480}));
  EXPECT_NE(result.name.find("camera cam-7"), std::string::npos) << result.name;
  EXPECT_NE(result.name.find("/event_camera/events"), std::string::npos) << result.name;

  EXPECT_THROW(read_all(path, "/imu"), std::runtime_error);  // a topic of another type
  try {
    read_all(path, "/nothing");
    ADD_FAILURE() << "no such topic";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/imu (sensor_msgs/msg/Imu)"), std::string::npos) << error.what();
  }
}

TEST(Rosbag2, AMessageOfThePacketFamilyIsReadByTheDefinitionTheBagKeeps) {
  TempDir dir;
  const auto path = dir.file("event_array.db3");
  const EventBatch events = sweep_events(800, 5'000'000);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(events, words);
  {
    BagWriter bag(path);
    bag.topic(1, "/event_camera/events", "event_array_msgs/msg/EventArray");
    bag.definition(
        "event_array_msgs/msg/EventArray",
        "std_msgs/Header header\nstring encoding\nuint32 height\nuint32 width\nuint64 seq\nuint64 time_base\n"
        "bool is_bigendian\nuint8[] events\n");
    CdrWriter cdr(true);
    cdr.put<std::int32_t>(1700000000);
    cdr.put<std::uint32_t>(123);
    cdr.put_string("cam-9");
    cdr.put_string("evt3");
    cdr.put<std::uint32_t>(480);
    cdr.put<std::uint32_t>(640);
    cdr.put<std::uint64_t>(0);
    cdr.put<std::uint64_t>(0);
    cdr.put<std::uint8_t>(0);
    cdr.put_bytes(words);
    bag.message(1, 100, cdr.bytes());
  }
  const ReadAll result = read_all(path);
  EXPECT_EQ(result.error, "");
  EXPECT_EQ(result.events, events_of(events));
  EXPECT_EQ(result.sensor, (SensorSize{640, 480}));
}

TEST(Rosbag2, LibcaerPacketsCountFromTheirTimeBaseAcrossTheTimeWrap) {
  TempDir dir;
  const auto path = dir.file("davis.db3");
  auto record = [](std::vector<std::uint8_t>& out, int x, int y, bool on, std::int32_t time, bool valid = true) {
    append_le32(out, static_cast<std::uint32_t>(x) << 17 | static_cast<std::uint32_t>(y) << 2 | (on ? 2u : 0u) |
                         (valid ? 1u : 0u));
    append_le32(out, static_cast<std::uint32_t>(time));
  };
  {
    BagWriter bag(path);
    bag.topic(1, "/events", std::string(kRos2EventPacketType));
    PacketFields first{.frame_id = "davis", .width = 346, .height = 260, .encoding = "libcaer", .events = {}};
    first.time_base = 7'000'000'000'123ULL;  // ns; not a whole us
    record(first.events, 1, 2, true, 10);
    record(first.events, 3, 4, false, 2147483640);
    record(first.events, 5, 6, true, 3);  // the 31-bit time wrapped inside the packet
    record(first.events, 9, 9, true, 4, /*valid=*/false);
    bag.message(1, 1, event_packet_cdr(first));
    PacketFields second = first;
    second.events.clear();
    second.time_base = first.time_base + (std::uint64_t{1} << 31) * 1000;  // the next packet's base carries the wrap
    record(second.events, 7, 8, false, 20);
    bag.message(1, 2, event_packet_cdr(second));
  }
  const ReadAll result = read_all(path);
  EXPECT_EQ(result.error, "");
  const Timestamp base = 7'000'000'000;
  const Timestamp wrap = Timestamp{1} << 31;
  EXPECT_EQ(result.events, (std::vector<Event>{{base + 10, 1, 2, 1},
                                               {base + 2147483640, 3, 4, -1},
                                               {base + wrap + 3, 5, 6, 1},
                                               {base + wrap + 20, 7, 8, -1}}));
  EXPECT_EQ(result.counts.skipped_words, 1u);  // the invalid record
  EXPECT_EQ(result.sensor, (SensorSize{346, 260}));
}

TEST(Rosbag2, LibcaerCompressedColumnsVectorsAndPerPacketTime) {
  TempDir dir;
  const auto path = dir.file("cmp.db3");
  {
    BagWriter bag(path);
    bag.topic(1, "/events", std::string(kRos2EventPacketType));
    PacketFields packet{.frame_id = "davis", .width = 346, .height = 260, .encoding = "libcaer_cmp", .events = {}};
    packet.time_base = 2'000'000;  // 2000 us
    // t = 0x001 << 12 | 0x005 us: x 17, one event (y 3, ON), then a vector at base y 8 (OFF): 8 and 10;
    // an unknown code 0x9, skipped; then x 18 and one event at y 260 - 1.
    for (const std::uint16_t word :
         std::initializer_list<std::uint16_t>{0x0001, 0x1005, 0x2011, 0x3803, 0x4008, 0x5005, 0x9ABC, 0x2012, 0x3103}) {
      append_le16(packet.events, word);
    }
    bag.message(1, 1, event_packet_cdr(packet));
    packet.events.clear();
    packet.time_base = 3'000'000;  // the time starts again at the next packet's base; x carries over
    for (const std::uint16_t word : std::initializer_list<std::uint16_t>{0x1002, 0x3804})
      append_le16(packet.events, word);
    bag.message(1, 2, event_packet_cdr(packet));
  }
  const ReadAll result = read_all(path);
  EXPECT_EQ(result.error, "");
  const Timestamp t = 2000 + (1 << 12) + 5;
  EXPECT_EQ(result.events,
            (std::vector<Event>{{t, 17, 3, 1}, {t, 17, 8, -1}, {t, 17, 10, -1}, {t, 18, 259, -1}, {3002, 18, 4, 1}}));
  EXPECT_EQ(result.counts.skipped_words, 1u);
}

TEST(Rosbag2, AnUnknownEncodingOrABrokenMessageIsAnErrorAfterTheEventsBeforeIt) {
  TempDir dir;
  const auto path = dir.file("odd.db3");
  const EventBatch events = sweep_events(50, 1000);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(events, words);
  {
    BagWriter bag(path);
    bag.topic(1, "/events", std::string(kRos2EventPacketType));
    PacketFields good;
    good.events = words;
    bag.message(1, 1, event_packet_cdr(good));
    PacketFields odd = good;
    odd.encoding = "evt4";
    bag.message(1, 2, event_packet_cdr(odd));
  }
  ReadAll result = read_all(path);
  EXPECT_EQ(result.events, events_of(events));
  EXPECT_NE(result.error.find("no decoder for the event encoding 'evt4'"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("odd.db3"), std::string::npos) << result.error;

  {
    BagWriter bag(path);
    bag.topic(1, "/events", std::string(kRos2EventPacketType));
    PacketFields good;
    good.events = words;
    bag.message(1, 1, event_packet_cdr(good));
    auto broken = event_packet_cdr(good);
    broken.resize(30);
    bag.message(1, 2, broken);
  }
  result = read_all(path);
  EXPECT_EQ(result.events, events_of(events));
  EXPECT_NE(result.error.find("message id 2"), std::string::npos) << result.error;
}

/// The "mono" encoding's 64-bit word: [31:0] ns after the time base, [47:32] x, [62:48] y, [63] polarity.
void append_mono(std::vector<std::uint8_t>& out, std::uint32_t dt_ns, std::uint16_t x, std::uint16_t y, bool on) {
  append_le32(out, dt_ns);
  append_le32(out, x | static_cast<std::uint32_t>(y) << 16 | (on ? 0x80000000u : 0u));
}

TEST(Rosbag2, MonoPacketsCountNanosecondsFromTheirTimeBase) {
  TempDir dir;
  const auto path = dir.file("mono.db3");
  {
    BagWriter bag(path);
    bag.topic(1, "/events", std::string(kRos2EventPacketType));
    PacketFields packet{.frame_id = "imx636", .width = 1280, .height = 720, .encoding = "mono", .events = {}};
    packet.time_base = 5'000'000'000'500ULL;  // ns
    append_mono(packet.events, 0, 1279, 719, true);
    append_mono(packet.events, 499, 0, 0, false);              // 5'000'000'000'999 ns: still the same us
    append_mono(packet.events, 4'000'000'000u, 17, 33, true);  // 4 s on: the full 32 bits
    bag.message(1, 1, event_packet_cdr(packet));
    packet.events.resize(12);  // a word cut short
    bag.message(1, 2, event_packet_cdr(packet));
  }
  const ReadAll result = read_all(path);
  const Timestamp base = 5'000'000'000;
  EXPECT_EQ(result.events,
            (std::vector<Event>{
                {base, 1279, 719, 1}, {base, 0, 0, -1}, {base + 4'000'000, 17, 33, 1}, {base, 1279, 719, 1}}));
  EXPECT_NE(result.error.find("inside an 8-byte event"), std::string::npos) << result.error;
  EXPECT_EQ(result.sensor, (SensorSize{1280, 720}));
}

/// A dvs_msgs/msg/EventArray in CDR: each event's fields aligned to their size, so events are padded
/// differently depending on where they start.
std::vector<std::uint8_t> event_array_cdr(const EventBatch& events, bool little_endian) {
  CdrWriter cdr(little_endian);
  cdr.put<std::int32_t>(1700000000);
  cdr.put<std::uint32_t>(9);
  cdr.put_string("dvxplorer");
  cdr.put<std::uint32_t>(480);  // height
  cdr.put<std::uint32_t>(640);  // width
  cdr.put(static_cast<std::uint32_t>(events.size()));
  for (std::size_t i = 0; i < events.size(); ++i) {
    cdr.put(events.x[i]);
    cdr.put(events.y[i]);
    cdr.put(static_cast<std::int32_t>(events.t[i] / 1'000'000));
    cdr.put(static_cast<std::uint32_t>(events.t[i] % 1'000'000 * 1000));
    cdr.put<std::uint8_t>(events.p[i] > 0 ? 1 : 0);
  }
  return cdr.bytes();
}

TEST(Rosbag2, DvsEventArraysInCdrOfEitherByteOrder) {
  TempDir dir;
  const auto path = dir.file("dvs.db3");
  const EventBatch events = sweep_events(700, 1'700'000'000'000'000);
  {
    BagWriter bag(path);
    bag.topic(1, "/dvs/events", std::string(kRos2EventArrayType));
    EventBatch part;
    for (std::size_t i = 0; i < events.size(); ++i) {
      part.push_back(events.t[i], events.x[i], events.y[i], events.p[i]);
      if (part.size() == 233 || i + 1 == events.size()) {
        bag.message(1, static_cast<std::int64_t>(i), event_array_cdr(part, i % 2 == 0));
        part.clear();
      }
    }
  }
  const ReadAll result = read_all(path);
  EXPECT_EQ(result.error, "");
  EXPECT_EQ(result.events, events_of(events));
  EXPECT_EQ(result.sensor, (SensorSize{640, 480}));
  EXPECT_NE(result.name.find("/dvs/events (dvs_msgs/msg/EventArray), camera dvxplorer"), std::string::npos)
      << result.name;
}

// ---- ROS 1 bags -----------------------------------------------------------------------------------

void put32(std::vector<std::uint8_t>& out, std::uint32_t value) { append_le32(out, value); }
void put_string(std::vector<std::uint8_t>& out, const std::string& text) {
  put32(out, static_cast<std::uint32_t>(text.size()));
  out.insert(out.end(), text.begin(), text.end());
}
void put_header(std::vector<std::uint8_t>& out, const std::string& frame_id) {
  put32(out, 7);  // seq
  put32(out, 1700000000);
  put32(out, 5);
  put_string(out, frame_id);
}

/// A dvs_msgs/EventArray as ROS 1 serializes it.
RawRosMessage dvs_event_array(const EventBatch& events, std::size_t from, std::size_t to) {
  RawRosMessage message{std::string(kRos1EventArrayType), {}, {}};
  put_header(message.bytes, "dvs");
  put32(message.bytes, 180);  // height
  put32(message.bytes, 240);  // width
  put32(message.bytes, static_cast<std::uint32_t>(to - from));
  for (std::size_t i = from; i < to; ++i) {
    append_le16(message.bytes, events.x[i]);
    append_le16(message.bytes, events.y[i]);
    put32(message.bytes, static_cast<std::uint32_t>(events.t[i] / 1'000'000));
    put32(message.bytes, static_cast<std::uint32_t>(events.t[i] % 1'000'000 * 1000));
    message.bytes.push_back(events.p[i] > 0 ? 1 : 0);
  }
  return message;
}

TEST(Rosbag1, DvsEventArraysInEveryChunkCompressionAndEventPackets) {
  TempDir dir;
  const auto path = dir.file("ecd.bag");
  EventBatch events;
  for (int i = 0; i < 3000; ++i) {
    events.push_back(1'468'940'000'000'000 + 17 * i, static_cast<std::uint16_t>(i % 240),
                     static_cast<std::uint16_t>(i % 180), i % 2 ? 1 : -1);
  }
  for (const auto compression :
       {rosbag::compression::Uncompressed, rosbag::compression::BZ2, rosbag::compression::LZ4}) {
    SCOPED_TRACE(static_cast<int>(compression));
    {
      rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
      bag.setCompression(compression);
      bag.setChunkThreshold(4096);  // many chunks
      for (std::size_t at = 0; at < events.size(); at += 250) {
        const ros::Time stamp(static_cast<double>(events.t[at]) * 1e-6);
        bag.write("/imu", stamp, RawRosMessage{"sensor_msgs/Imu", std::vector<std::uint8_t>(20, 1), {}});
        bag.write("/dvs/events", stamp, dvs_event_array(events, at, std::min(events.size(), at + 250)));
      }
    }
    const ReadAll result = read_all(path);
    EXPECT_EQ(result.error, "");
    EXPECT_EQ(result.events, events_of(events));
    EXPECT_EQ(result.sensor, (SensorSize{240, 180}));
    EXPECT_NE(result.name.find("ROS 1 bag, /dvs/events (dvs_msgs/EventArray), camera dvs"), std::string::npos)
        << result.name;
  }
  try {
    read_all(path, "/imu");
    ADD_FAILURE() << "a topic of another type";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("sensor_msgs/Imu"), std::string::npos) << error.what();
  }

  // event_camera_msgs/EventPacket with evt3, as the ROS 1 drivers record it.
  const EventBatch sweep = sweep_events(500, 2'000'000);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(sweep, words);
  {
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    RawRosMessage packet{std::string(kRos1EventPacketType), {}, {}};
    put_header(packet.bytes, "prophesee");
    put32(packet.bytes, 480);
    put32(packet.bytes, 640);
    for (const std::uint64_t value : {std::uint64_t{3}, std::uint64_t{0}}) {  // seq, time_base
      for (int i = 0; i < 8; ++i) packet.bytes.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
    }
    put_string(packet.bytes, "evt3");
    packet.bytes.push_back(0);  // is_bigendian
    put_string(packet.bytes, std::string(words.begin(), words.end()));
    bag.write("/events", ros::Time(2.0), packet);
  }
  const ReadAll packets = read_all(path);
  EXPECT_EQ(packets.error, "");
  EXPECT_EQ(packets.events, events_of(sweep));
  EXPECT_EQ(packets.sensor, (SensorSize{640, 480}));
}

// event_array_msgs/EventArray, event_camera_msgs/EventPacket's former name, with its fields in an
// order of its own: read by the definition the bag or file stores for the topic.
constexpr const char* kEventArrayFamilyDefinition =
    "# a message of the EventPacket family\n"
    "std_msgs/Header header\n"
    "string encoding\n"
    "uint32 height\n"
    "uint32 width\n"
    "uint64 seq  # sequence number\n"
    "uint64 time_base\n"
    "uint8 FLAG=1\n"
    "bool is_bigendian\n"
    "uint8[] events\n"
    "================================================================================\n"
    "MSG: std_msgs/Header\n"
    "uint32 seq\n"
    "time stamp\n"
    "string frame_id\n";

TEST(Rosbag1, AMessageOfThePacketFamilyIsReadByTheDefinitionItsConnectionStores) {
  TempDir dir;
  const auto path = dir.file("event_array.bag");
  const EventBatch sweep = sweep_events(500, 2'000'000);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(sweep, words);
  RawRosMessage packet{"event_array_msgs/EventArray", {}, kEventArrayFamilyDefinition};
  put_header(packet.bytes, "prophesee");
  put_string(packet.bytes, "evt3");
  put32(packet.bytes, 480);
  put32(packet.bytes, 640);
  for (const std::uint64_t value : {std::uint64_t{3}, std::uint64_t{0}}) {  // seq, time_base
    for (int i = 0; i < 8; ++i) packet.bytes.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  }
  packet.bytes.push_back(0);  // is_bigendian
  put_string(packet.bytes, std::string(words.begin(), words.end()));
  {
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    bag.write("/event_camera/events", ros::Time(2.0), packet);
  }
  const ReadAll read = read_all(path);
  EXPECT_EQ(read.error, "");
  EXPECT_EQ(read.events, events_of(sweep));
  EXPECT_EQ(read.sensor, (SensorSize{640, 480}));
  // Without a definition the type tells nothing: refused, naming what is read.
  packet.definition.clear();
  {
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    bag.write("/event_camera/events", ros::Time(2.0), packet);
  }
  try {
    (void)open_recording(path, std::nullopt, "", 1000);
    ADD_FAILURE() << "read a message type without its definition";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("no topic of an event type"), std::string::npos) << error.what();
  }
}

TEST(Rosbag1, ABrokenMessageIsAnErrorNamingItAfterTheEventsBeforeIt) {
  TempDir dir;
  const auto path = dir.file("broken.bag");
  const EventBatch events = sweep_events(100, 1'000'000);
  {
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    bag.write("/dvs/events", ros::Time(1.0), dvs_event_array(events, 0, 100));
    RawRosMessage broken = dvs_event_array(events, 0, 100);
    broken.bytes.resize(broken.bytes.size() - 5);  // the count says 100 events, the bytes hold less
    bag.write("/dvs/events", ros::Time(2.0), broken);
  }
  const ReadAll result = read_all(path);
  std::vector<Event> expected = events_of(events);
  EXPECT_EQ(result.events, expected);
  EXPECT_NE(result.error.find("message 1 of /dvs/events"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("broken.bag"), std::string::npos) << result.error;
}

// ---- AEDAT 4.0 ------------------------------------------------------------------------------------

std::vector<std::uint8_t> compress(aedat4::CompressionType compression, const std::vector<std::uint8_t>& data) {
  std::vector<std::uint8_t> out;
  switch (compression) {
    case aedat4::CompressionType::LZ4: {
      out.resize(LZ4F_compressFrameBound(data.size(), nullptr));
      out.resize(LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), nullptr));
      return out;
    }
    case aedat4::CompressionType::ZSTD: {
      out.resize(ZSTD_compressBound(data.size()));
      out.resize(ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 3));
      return out;
    }
    default:
      return data;
  }
}

/// How a writer lays out its FlatBuffers (the header and the packets).
enum class FlatBufferLayout {
  Dv,     ///< as DV writes them: size-prefixed, with identifiers, fields in the schema's order
  Other,  ///< every field written, in another order, and no identifiers
  /// as the aedat library writes them: each finished as a plain buffer, its size then put in front,
  /// so 8-byte fields are aligned from the buffer's first byte, not from the prefix
  SizeInFront,
};

/// The builder's buffer as the layout stores it: size-prefixed already, or with its size put in front.
std::vector<std::uint8_t> stored(const flatbuffers::FlatBufferBuilder& builder, FlatBufferLayout layout) {
  std::vector<std::uint8_t> bytes;
  if (layout == FlatBufferLayout::SizeInFront) append_le32(bytes, static_cast<std::uint32_t>(builder.GetSize()));
  bytes.insert(bytes.end(), builder.GetBufferPointer(), builder.GetBufferPointer() + builder.GetSize());
  return bytes;
}

/// A DV event packet of events [from, to).
std::vector<std::uint8_t> dv_event_packet(const EventBatch& events, std::size_t from, std::size_t to,
                                          FlatBufferLayout layout) {
  flatbuffers::FlatBufferBuilder builder;
  std::vector<dv::Event> elements;
  for (std::size_t i = from; i < to; ++i) {
    elements.emplace_back(events.t[i], static_cast<std::int16_t>(events.x[i]), static_cast<std::int16_t>(events.y[i]),
                          events.p[i] > 0);
  }
  const auto packet = dv::CreateEventPacket(builder, builder.CreateVectorOfStructs(elements));
  switch (layout) {
    case FlatBufferLayout::Dv:
      dv::FinishSizePrefixedEventPacketBuffer(builder, packet);
      break;
    case FlatBufferLayout::Other:
      builder.FinishSizePrefixed(packet);
      break;
    case FlatBufferLayout::SizeInFront:
      builder.Finish(packet);
      break;
  }
  return stored(builder, layout);
}

const char* kInfoXml = R"(<dv version="2.0">
    <node name="outInfo" path="/mainloop/Recorder/outInfo/">
        <node name="1" path="/mainloop/Recorder/outInfo/1/">
            <attr key="typeIdentifier" type="string">IMUS</attr>
        </node>
        <node name="4" path="/mainloop/Recorder/outInfo/4/">
            <attr key="compression" type="string">LZ4</attr>
            <attr key="typeIdentifier" type="string">EVTS</attr>
            <node name="info" path="/mainloop/Recorder/outInfo/4/info/">
                <attr key="sizeX" type="int">346</attr>
                <attr key="sizeY" type="int">260</attr>
                <attr key="source" type="string">DAVIS346_00000499</attr>
            </node>
        </node>
    </node>
</dv>)";

/// An AEDAT 4.0 file: the events in packets of `per_packet` on stream 4, an IMU packet (stream 1)
/// between them. Returns where each packet header starts.
std::vector<std::uint64_t> write_aedat4(const std::filesystem::path& path, const EventBatch& events,
                                        std::size_t per_packet, aedat4::CompressionType compression,
                                        FlatBufferLayout layout = FlatBufferLayout::Dv) {
  std::vector<std::uint8_t> file(kAedat4Magic.begin(), kAedat4Magic.end());
  flatbuffers::FlatBufferBuilder header_builder;
  switch (layout) {
    case FlatBufferLayout::Dv:
      aedat4::FinishSizePrefixedIOHeaderBuffer(header_builder,
                                               aedat4::CreateIOHeaderDirect(header_builder, compression, -1, kInfoXml));
      break;
    case FlatBufferLayout::Other: {
      // The fields added in reverse: the table lists the string first and the compression last.
      header_builder.ForceDefaults(true);
      const auto info = header_builder.CreateString(kInfoXml);
      aedat4::IOHeaderBuilder header(header_builder);
      header.add_infoNode(info);
      header.add_dataTablePosition(-1);
      header.add_compression(compression);
      header_builder.FinishSizePrefixed(header.Finish());
      break;
    }
    case FlatBufferLayout::SizeInFront:
      header_builder.ForceDefaults(true);  // the 8-byte dataTablePosition is written, aligned from the buffer's start
      header_builder.Finish(aedat4::CreateIOHeaderDirect(header_builder, compression, -1, kInfoXml));
      break;
  }
  const auto header = stored(header_builder, layout);
  file.insert(file.end(), header.begin(), header.end());
  std::vector<std::uint64_t> packet_starts;
  auto packet = [&](std::int32_t stream, const std::vector<std::uint8_t>& payload) {
    packet_starts.push_back(file.size());
    append_le32(file, static_cast<std::uint32_t>(stream));
    const auto compressed = compress(compression, payload);
    append_le32(file, static_cast<std::uint32_t>(compressed.size()));
    file.insert(file.end(), compressed.begin(), compressed.end());
  };
  for (std::size_t at = 0; at < events.size(); at += per_packet) {
    packet(4, dv_event_packet(events, at, std::min(events.size(), at + per_packet), layout));
    packet(1, std::vector<std::uint8_t>(40, 7));  // not events: skipped
  }
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  return packet_starts;
}

TEST(Aedat4, PolarityPacketsInEveryCompressionWithSensorAndCameraFromTheHeader) {
  TempDir dir;
  EventBatch events;
  for (int i = 0; i < 2000; ++i) {
    events.push_back(1'605'537'493'718'345 + i, static_cast<std::uint16_t>(i % 346),
                     static_cast<std::uint16_t>(i % 260), i % 2 ? 1 : -1);
  }
  for (const auto compression :
       {aedat4::CompressionType::NONE, aedat4::CompressionType::LZ4, aedat4::CompressionType::ZSTD}) {
    SCOPED_TRACE(static_cast<int>(compression));
    const auto path = dir.file("rec.aedat4");
    write_aedat4(path, events, 300, compression);
    const ReadAll result = read_all(path);
    EXPECT_EQ(result.error, "");
    EXPECT_EQ(result.events, events_of(events));
    EXPECT_EQ(result.sensor, (SensorSize{346, 260}));
    EXPECT_NE(result.name.find("camera DAVIS346_00000499"), std::string::npos) << result.name;
  }
}

// A header of another writer: any field order, no file identifier; it reads as DV's.
TEST(Aedat4, AHeaderInAnotherFieldOrderWithoutTheIdentifierReadsInEveryCompression) {
  TempDir dir;
  const EventBatch events = sweep_events(1000, 100);
  for (const auto compression :
       {aedat4::CompressionType::NONE, aedat4::CompressionType::LZ4, aedat4::CompressionType::ZSTD}) {
    SCOPED_TRACE(static_cast<int>(compression));
    const auto path = dir.file("other.aedat4");
    write_aedat4(path, events, 300, compression, FlatBufferLayout::Other);
    const ReadAll result = read_all(path);
    EXPECT_EQ(result.error, "");
    EXPECT_EQ(result.events, events_of(events));
    EXPECT_EQ(result.sensor, (SensorSize{346, 260}));
  }
}

// The aedat library (Python/Rust) finishes each FlatBuffer plain and puts its size in front, so its
// 8-byte fields sit 4 bytes off the alignment a size-prefixed buffer has: the header, and every event
// packet, read as DV's do.
TEST(Aedat4, FlatBuffersWithTheirSizePutInFrontReadAsDvsInEveryCompression) {
  TempDir dir;
  const EventBatch events = sweep_events(1000, 100);
  const auto dv_path = dir.file("dv.aedat4");
  write_aedat4(dv_path, events, 300, aedat4::CompressionType::LZ4);
  const ReadAll from_dv = read_all(dv_path);
  ASSERT_EQ(from_dv.error, "");
  for (const auto compression :
       {aedat4::CompressionType::NONE, aedat4::CompressionType::LZ4, aedat4::CompressionType::ZSTD}) {
    SCOPED_TRACE(static_cast<int>(compression));
    const auto path = dir.file("aedat-library.aedat4");
    write_aedat4(path, events, 300, compression, FlatBufferLayout::SizeInFront);
    // The fixture is what real files hold: a verifier aligned from the prefix refuses its header.
    std::ifstream in(path, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::uint32_t header_size = 0;
    std::memcpy(&header_size, bytes.data() + kAedat4Magic.size(), 4);
    std::vector<std::uint64_t> header((4 + header_size + 7) / 8);
    std::memcpy(header.data(), bytes.data() + kAedat4Magic.size(), 4 + header_size);
    EXPECT_FALSE(flatbuffers::Verifier(reinterpret_cast<const std::uint8_t*>(header.data()), 4 + header_size)
                     .VerifySizePrefixedBuffer<aedat4::IOHeader>(nullptr));

    const ReadAll result = read_all(path);
    EXPECT_EQ(result.error, "");
    EXPECT_EQ(result.events, from_dv.events);
    EXPECT_EQ(result.sensor, from_dv.sensor);
    EXPECT_EQ(result.name.substr(result.name.find("camera")), from_dv.name.substr(from_dv.name.find("camera")));
  }
}

// A buffer that holds its size and nothing more (or less than a root offset) is no table, whether
// its size field says so or not; the fuzzer found this reading an empty copy.
TEST(Aedat4, ABufferTooShortForARootIsRefusedInEitherLayout) {
  std::vector<std::uint64_t> scratch;
  for (std::size_t length = 0; length < 8; ++length) {
    for (const std::uint32_t size_field : {0u, static_cast<std::uint32_t>(length >= 4 ? length - 4 : 0), 40u}) {
      SCOPED_TRACE(testing::Message() << length << " bytes, size field " << size_field);
      std::vector<std::uint8_t> bytes(length, 0);
      if (length >= 4) std::memcpy(bytes.data(), &size_field, 4);
      EXPECT_EQ(verified_size_prefixed_root<dv::EventPacket>(bytes, scratch), nullptr);
      EXPECT_EQ(verified_size_prefixed_root<aedat4::IOHeader>(bytes, scratch), nullptr);
    }
  }
}

TEST(Aedat4, ACutFileGivesEveryWholePacketThenAnErrorAtItsOffset) {
  TempDir dir;
  const auto path = dir.file("cut.aedat4");
  const EventBatch events = sweep_events(1000, 100);
  const auto starts = write_aedat4(path, events, 250, aedat4::CompressionType::LZ4);
  // Cut inside the third event packet (the fifth packet: event, IMU, event, IMU, event).
  std::filesystem::resize_file(path, starts[4] + 20);
  const ReadAll result = read_all(path);
  const std::vector<Event> written = events_of(events);
  EXPECT_EQ(result.events, std::vector<Event>(written.begin(), written.begin() + 500));
  EXPECT_NE(result.error.find("cut.aedat4: byte " + std::to_string(starts[4])), std::string::npos) << result.error;

  // A header that is no FlatBuffer is refused at once, naming the file.
  std::ofstream(path, std::ios::binary) << kAedat4Magic << std::string("\x10\0\0\0", 4) << std::string(16, 'x');
  EXPECT_THROW(read_all(path), FormatError);
}

// ---- MCAP -----------------------------------------------------------------------------------------

/// An MCAP file as rosbag2's MCAP storage writes one: schemas and channels, then messages, in chunks
/// (or, with no `compression`, at the top level), then DataEnd, an empty summary and the footer.
class McapWriter {
 public:
  explicit McapWriter(std::optional<std::string> compression) : compression_(std::move(compression)) {
    file_.assign(kMcapMagic.begin(), kMcapMagic.end());
    record(file_, 0x01, string_field("ros2") + string_field("evldt test"));
  }
  void schema(std::uint16_t id, const std::string& name, const std::string& encoding = "ros2msg",
              const std::string& definition = "# definition") {
    record(target(), 0x03, le(id, 2) + string_field(name) + string_field(encoding) + string_field(definition));
  }
  void channel(std::uint16_t id, std::uint16_t schema, const std::string& topic, const std::string& encoding = "cdr") {
    record(target(), 0x04, le(id, 2) + le(schema, 2) + string_field(topic) + string_field(encoding) + le(0, 4));
  }
  void message(std::uint16_t channel, std::uint64_t time, const std::vector<std::uint8_t>& data) {
    record(target(), 0x05,
           le(channel, 2) + le(sequence_++, 4) + le(time, 8) + le(time, 8) + std::string(data.begin(), data.end()));
  }
  /// Ends the chunk being written; returns where it starts in the file.
  std::uint64_t end_chunk(bool corrupt_crc = false) {
    const std::uint64_t at = file_.size();
    if (!compression_ || chunk_.empty()) return at;
    std::vector<std::uint8_t> records(chunk_.begin(), chunk_.end());
    std::vector<std::uint8_t> stored = records;
    if (*compression_ == "lz4") stored = compress(aedat4::CompressionType::LZ4, records);
    if (*compression_ == "zstd") stored = compress(aedat4::CompressionType::ZSTD, records);
    const auto crc = static_cast<std::uint32_t>(crc32(0, records.data(), static_cast<uInt>(records.size()))) ^
                     (corrupt_crc ? 1u : 0u);
    record(file_, 0x06,
           le(0, 8) + le(0, 8) + le(records.size(), 8) + le(crc, 4) + string_field(*compression_) +
               le(stored.size(), 8) + std::string(stored.begin(), stored.end()));
    chunk_.clear();
    return at;
  }
  /// DataEnd, the footer and the closing magic; `path` written.
  void finish(const std::filesystem::path& path, bool close = true) {
    end_chunk();
    if (close) {
      record(file_, 0x0F, le(0, 4));
      record(file_, 0x02, le(0, 8) + le(0, 8) + le(0, 4));
      file_.insert(file_.end(), kMcapMagic.begin(), kMcapMagic.end());
    }
    std::ofstream(path, std::ios::binary).write(file_.data(), static_cast<std::streamsize>(file_.size()));
  }

 private:
  static std::string le(std::uint64_t value, int bytes) {
    std::string out;
    for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>(value >> (8 * i)));
    return out;
  }
  static std::string string_field(const std::string& text) { return le(text.size(), 4) + text; }
  static void record(std::string& out, std::uint8_t opcode, const std::string& content) {
    out.push_back(static_cast<char>(opcode));
    out += le(content.size(), 8) + content;
  }
  std::string& target() { return compression_ ? chunk_ : file_; }

  std::optional<std::string> compression_;
  std::string file_, chunk_;
  std::uint32_t sequence_ = 0;
};

TEST(Mcap, EventPacketsInChunksOfEveryCompressionOrNone) {
  TempDir dir;
  const auto path = dir.file("rec.mcap");
  const EventBatch events = sweep_events(4000, 9'000'000);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(events, words);
  for (const std::optional<std::string>& compression :
       {std::optional<std::string>(), std::optional<std::string>(""), std::optional<std::string>("lz4"),
        std::optional<std::string>("zstd")}) {
    SCOPED_TRACE(compression.value_or("no chunks"));
    McapWriter mcap(compression);
    mcap.schema(1, "sensor_msgs/msg/Imu");
    mcap.channel(1, 1, "/imu");
    mcap.schema(2, std::string(kRos2EventPacketType));
    mcap.channel(2, 2, "/event_camera/events");
    PacketFields fields;
    for (std::size_t at = 0, seq = 0; at < words.size(); ++seq) {
      const std::size_t size = std::min<std::size_t>(words.size() - at, 2 * (41 + 97 * (seq % 4)));
      fields.events.assign(words.begin() + static_cast<std::ptrdiff_t>(at),
                           words.begin() + static_cast<std::ptrdiff_t>(at + size));
      mcap.message(1, seq, std::vector<std::uint8_t>(24, 3));
      mcap.message(2, seq, event_packet_cdr(fields));
      at += size;
      if (seq % 7 == 6) mcap.end_chunk();
    }
    mcap.finish(path);
    const ReadAll result = read_all(path);
    EXPECT_EQ(result.error, "");
    EXPECT_EQ(result.events, events_of(events));
    EXPECT_EQ(result.sensor, (SensorSize{640, 480}));
    EXPECT_NE(result.name.find("MCAP, /event_camera/events (event_camera_msgs/msg/EventPacket), camera cam-7"),
              std::string::npos)
        << result.name;
  }
  try {
    read_all(path, "/imu");
    ADD_FAILURE() << "a channel of another type";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/imu is of type sensor_msgs/msg/Imu"), std::string::npos) << error.what();
  }
  try {
    read_all(path, "/nothing");
    ADD_FAILURE() << "no such channel";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("channels: /imu (sensor_msgs/msg/Imu, cdr), /event_camera/events"),
              std::string::npos)
        << error.what();
  }
}

TEST(Mcap, AMessageOfThePacketFamilyIsReadByItsSchemasDefinition) {
  TempDir dir;
  const auto path = dir.file("event_array.mcap");
  const EventBatch sweep = sweep_events(500, 2'000'000);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(sweep, words);
  std::vector<std::uint8_t> message;
  put_header(message, "prophesee");
  put_string(message, "evt3");
  put32(message, 480);
  put32(message, 640);
  for (int i = 0; i < 16; ++i) message.push_back(0);  // seq, time_base
  message.push_back(0);                               // is_bigendian
  put_string(message, std::string(words.begin(), words.end()));
  McapWriter mcap(std::nullopt);
  mcap.schema(1, "event_array_msgs/EventArray", "ros1msg", kEventArrayFamilyDefinition);
  mcap.channel(1, 1, "/event_camera/events", "ros1");
  mcap.message(1, 0, message);
  mcap.finish(path);
  const ReadAll read = read_all(path);
  EXPECT_EQ(read.error, "");
  EXPECT_EQ(read.events, events_of(sweep));
  EXPECT_EQ(read.sensor, (SensorSize{640, 480}));
}

TEST(Mcap, Ros1EventArraysAndTopicChoice) {
  TempDir dir;
  const auto path = dir.file("ecd.mcap");
  EventBatch first, second;
  for (int i = 0; i < 300; ++i) {
    first.push_back(1'000'000 + i, static_cast<std::uint16_t>(i % 240), 5, 1);
    second.push_back(2'000'000 + i, 7, static_cast<std::uint16_t>(i % 180), -1);
  }
  McapWriter mcap("zstd");
  mcap.schema(1, std::string(kRos1EventArrayType), "ros1msg");
  mcap.channel(1, 1, "/dvs/events", "ros1");
  mcap.channel(2, 1, "/dvs_right/events", "ros1");
  mcap.message(1, 1, dvs_event_array(first, 0, first.size()).bytes);
  mcap.message(2, 1, dvs_event_array(second, 0, second.size()).bytes);
  mcap.finish(path);
  const ReadAll left = read_all(path);
  EXPECT_EQ(left.error, "");
  EXPECT_EQ(left.events, events_of(first));
  EXPECT_EQ(left.sensor, (SensorSize{240, 180}));
  const ReadAll right = read_all(path, "/dvs_right/events");
  EXPECT_EQ(right.events, events_of(second));
}

/// A sensor_msgs/msg/Image in CDR: a 4 x 2 mono8 frame whose pixels count up from `first`.
std::vector<std::uint8_t> image_cdr(std::int32_t sec, std::uint32_t nanosec, std::uint8_t first) {
  CdrWriter cdr(true);
  cdr.put<std::int32_t>(sec);
  cdr.put<std::uint32_t>(nanosec);
  cdr.put_string("davis");
  cdr.put<std::uint32_t>(2);  // height
  cdr.put<std::uint32_t>(4);  // width
  cdr.put_string("mono8");
  cdr.put<std::uint8_t>(0);
  cdr.put<std::uint32_t>(4);  // step
  std::vector<std::uint8_t> pixels(8);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint8_t>(first + i);
  cdr.put_bytes(pixels);
  return cdr.bytes();
}

TEST(Mcap, ImagesOfAChannelBesideTheEvents) {
  TempDir dir;
  const auto path = dir.file("frames.mcap");
  McapWriter mcap("lz4");
  mcap.schema(1, std::string(kRos2EventPacketType));
  mcap.schema(2, "sensor_msgs/msg/Image");
  mcap.channel(1, 1, "/events");
  mcap.channel(2, 2, "/dvs/image_raw");
  PacketFields fields;
  fields.events = {1, 2, 3};
  for (std::uint8_t k = 0; k < 3; ++k) {
    mcap.message(1, k, event_packet_cdr(fields));
    mcap.message(2, k, image_cdr(1700000000, 250'000'000u * k, static_cast<std::uint8_t>(10 * k)));
  }
  mcap.finish(path);
  const auto images = open_image_container(path, "");
  ASSERT_TRUE(images);
  EXPECT_EQ(images->description(), "MCAP, /dvs/image_raw (sensor_msgs/msg/Image)");
  RecordingImage image;
  std::string location;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(images->next(image, location));
    EXPECT_EQ(image.t_us, 1'700'000'000'000'000 + 250'000 * k);
    EXPECT_EQ(image.width, 4u);
    EXPECT_EQ(image.height, 2u);
    EXPECT_EQ(image.encoding, "mono8");
    EXPECT_EQ(image.step, 4u);
    ASSERT_EQ(image.data.size(), 8u);
    EXPECT_EQ(image.data[7], 10 * k + 7) << location;
    EXPECT_NE(location.find("message " + std::to_string(k) + " of /dvs/image_raw"), std::string::npos) << location;
  }
  EXPECT_FALSE(images->next(image, location));
  try {
    open_mcap_images(path, "/events");
    ADD_FAILURE() << "an event channel holds no images";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(
        std::string(error.what())
            .find("channel /events is of type event_camera_msgs/msg/EventPacket (cdr), not sensor_msgs/msg/Image"),
        std::string::npos)
        << error.what();
  }
}

TEST(Mcap, CorruptCutOrUnclosedFilesGiveTheEventsBeforeThenAnError) {
  TempDir dir;
  const auto path = dir.file("bad.mcap");
  const EventBatch events = sweep_events(200, 3'000'000);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(events, words);
  PacketFields fields;
  fields.events = words;
  auto write = [&](bool corrupt_second_chunk, bool close) {
    McapWriter mcap("lz4");
    mcap.schema(1, std::string(kRos2EventPacketType));
    mcap.channel(1, 1, "/events");
    mcap.message(1, 1, event_packet_cdr(fields));
    mcap.end_chunk();
    mcap.message(1, 2, event_packet_cdr(fields));
    const std::uint64_t second = mcap.end_chunk(corrupt_second_chunk);
    mcap.finish(path, close);
    return second;
  };
  const std::vector<Event> one = events_of(events);

  std::uint64_t second = write(/*corrupt_second_chunk=*/true, /*close=*/true);
  ReadAll result = read_all(path);
  EXPECT_EQ(result.events, one);
  EXPECT_NE(result.error.find("bad.mcap: byte " + std::to_string(second)), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("CRC mismatch"), std::string::npos) << result.error;

  second = write(false, true);
  std::filesystem::resize_file(path, second + 30);  // cut inside the second chunk
  result = read_all(path);
  EXPECT_EQ(result.events, one);
  EXPECT_NE(result.error.find("does not fit in the file"), std::string::npos) << result.error;

  write(false, /*close=*/false);  // a recorder that stopped without closing the file
  result = read_all(path);
  EXPECT_EQ(result.events.size(), 2 * one.size());
  EXPECT_NE(result.error.find("without its footer"), std::string::npos) << result.error;

  std::ofstream(path, std::ios::binary) << kMcapMagic << "garbage";
  EXPECT_THROW(read_all(path), FormatError);
}

// ---- HDF5 -----------------------------------------------------------------------------------------

/// HDF5 fixtures written with the HDF5 C library, in the layouts of DSEC, MVSEC and Metavision.
class Hdf5Writer {
 public:
  explicit Hdf5Writer(const std::filesystem::path& path)
      : file_(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT)) {
    EXPECT_GE(file_, 0);
  }
  ~Hdf5Writer() { H5Fclose(file_); }
  void group(const char* name) { H5Gclose(H5Gcreate2(file_, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)); }
  /// A dataset of `dims` rows (x columns) of `file_type` from `data` of `memory_type`, in chunks
  /// through `filter` (0: none).
  void dataset(const char* name, hid_t file_type, hid_t memory_type, const void* data, std::vector<hsize_t> dims,
               H5Z_filter_t filter = 0, unsigned filter_flags = H5Z_FLAG_MANDATORY) {
    const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
    const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
    if (filter != 0) {
      std::vector<hsize_t> chunk = dims;
      chunk[0] = std::min<hsize_t>(dims[0], 10000);
      H5Pset_chunk(plist, static_cast<int>(chunk.size()), chunk.data());
      const unsigned blosc_options[7] = {0, 0, 0, 0, 5, 1, 0};  // level 5, byte shuffle, blosclz
      EXPECT_GE(H5Pset_filter(plist, filter, filter_flags, 7, blosc_options), 0);
    }
    const hid_t dataset = H5Dcreate2(file_, name, file_type, space, H5P_DEFAULT, plist, H5P_DEFAULT);
    EXPECT_GE(dataset, 0) << name;
    EXPECT_GE(H5Dwrite(dataset, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), 0) << name;
    H5Dclose(dataset);
    H5Pclose(plist);
    H5Sclose(space);
  }
  void string_attribute(const char* name, const std::string& value) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, value.size() + 1);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attribute = H5Acreate2(file_, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attribute, type, value.c_str());
    H5Aclose(attribute);
    H5Sclose(space);
    H5Tclose(type);
  }
  [[nodiscard]] hid_t file() const { return file_; }

 private:
  hid_t file_;
};

constexpr H5Z_filter_t kBlosc = 32001;

/// DSEC's layout: /events/{x, y, t, p} (t in us from /t_offset), blosc-compressed, and /ms_to_idx.
void write_dsec(const std::filesystem::path& path, const EventBatch& events, std::int64_t t_offset) {
  Hdf5Writer h5(path);
  h5.group("/events");
  std::vector<std::uint32_t> t;
  std::vector<std::uint8_t> p;
  for (std::size_t i = 0; i < events.size(); ++i) {
    t.push_back(static_cast<std::uint32_t>(events.t[i] - t_offset));
    p.push_back(events.p[i] > 0 ? 1 : 0);
  }
  const std::vector<hsize_t> n{events.size()};
  h5.dataset("/events/x", H5T_STD_U16LE, H5T_NATIVE_UINT16, events.x.data(), n, kBlosc);
  h5.dataset("/events/y", H5T_STD_U16LE, H5T_NATIVE_UINT16, events.y.data(), n, kBlosc);
  h5.dataset("/events/t", H5T_STD_U32LE, H5T_NATIVE_UINT32, t.data(), n, kBlosc);
  h5.dataset("/events/p", H5T_STD_U8LE, H5T_NATIVE_UINT8, p.data(), n, kBlosc);
  h5.dataset("/t_offset", H5T_STD_I64LE, H5T_NATIVE_INT64, &t_offset, {1});
  const std::vector<std::uint64_t> ms_to_idx{0, events.size()};
  h5.dataset("/ms_to_idx", H5T_STD_U64LE, H5T_NATIVE_UINT64, ms_to_idx.data(), {2});
}

TEST(Hdf5, DsecColumnsThroughTheBloscPluginInSlabs) {
  TempDir dir;
  const auto path = dir.file("events.h5");
  const std::int64_t t_offset = 1'500'000'000'000'000;
  EventBatch events;
  for (int i = 0; i < 150'000; ++i) {  // more than two slabs
    events.push_back(t_offset + 2 * i + 40, static_cast<std::uint16_t>((13 * i) % 640),
                     static_cast<std::uint16_t>((7 * i) % 480), i % 3 ? 1 : -1);
  }
  write_dsec(path, events, t_offset);
  {  // the fixture is blosc-compressed, so the plugin was found and used
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const hid_t dataset = H5Dopen2(file, "/events/t", H5P_DEFAULT);
    const hid_t plist = H5Dget_create_plist(dataset);
    EXPECT_EQ(H5Pget_nfilters(plist), 1);
    EXPECT_EQ(H5Pget_filter2(plist, 0, nullptr, nullptr, nullptr, 0, nullptr, nullptr), kBlosc);
    H5Pclose(plist);
    H5Dclose(dataset);
    H5Fclose(file);
  }
  const ReadAll result = read_all(path);
  EXPECT_EQ(result.error, "");
  EXPECT_EQ(result.events, events_of(events));
  EXPECT_EQ(result.sensor, (SensorSize{640, 480}));
  EXPECT_NE(result.name.find("HDF5, /events (columns x, y, t, p, t in us; 640x480 as DSEC's cameras: not in the file)"),
            std::string::npos)
      << result.name;
}

TEST(Hdf5, MvsecRowsInSecondsEitherCameraAndMetavisionRecords) {
  TempDir dir;
  const auto path = dir.file("mvsec_data.hdf5");
  std::vector<double> left, right;
  for (int i = 0; i < 1000; ++i) {
    for (const double value : {double(i % 346), double(i % 260), 1'504'645'177.5 + i * 1e-5, i % 2 ? 1.0 : -1.0})
      left.push_back(value);
    for (const double value : {double(i % 200), 3.0, 1'504'645'180.0 + i * 1e-6, 1.0}) right.push_back(value);
  }
  {
    Hdf5Writer h5(path);
    h5.group("/davis");
    h5.group("/davis/left");
    h5.group("/davis/right");
    h5.dataset("/davis/left/events", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, left.data(), {1000, 4});
    h5.dataset("/davis/right/events", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, right.data(), {1000, 4});
  }
  const ReadAll result = read_all(path);
  EXPECT_EQ(result.error, "");
  ASSERT_EQ(result.events.size(), 1000u);
  EXPECT_EQ(result.events[0], (Event{1'504'645'177'500'000, 0, 0, -1}));
  EXPECT_EQ(result.events[999], (Event{1'504'645'177'500'000 + 9990, 999 % 346, 999 % 260, 1}));
  EXPECT_EQ(result.sensor, (SensorSize{346, 260}));
  const ReadAll other = read_all(path, "davis/right/events");
  ASSERT_EQ(other.events.size(), 1000u);
  EXPECT_EQ(other.events[7], (Event{1'504'645'180'000'007, 7, 3, 1}));

  // Metavision's records, sensor size from its geometry attribute; an x off the sensor is kept for the
  // validator to drop and count.
  struct CdEvent {
    std::uint16_t x, y;
    std::int16_t p;
    std::int64_t t;
  };
  const std::vector<CdEvent> cd{{1279, 719, 1, 100}, {0, 0, 0, 250}, {70000 % 65536, 5, 1, 300}};
  const auto records = dir.file("recording.hdf5");
  {
    Hdf5Writer h5(records);
    h5.group("/CD");
    const hid_t type = H5Tcreate(H5T_COMPOUND, sizeof(CdEvent));
    H5Tinsert(type, "x", HOFFSET(CdEvent, x), H5T_NATIVE_UINT16);
    H5Tinsert(type, "y", HOFFSET(CdEvent, y), H5T_NATIVE_UINT16);
    H5Tinsert(type, "p", HOFFSET(CdEvent, p), H5T_NATIVE_INT16);
    H5Tinsert(type, "t", HOFFSET(CdEvent, t), H5T_NATIVE_INT64);
    h5.dataset("/CD/events", type, type, cd.data(), {cd.size()});
    H5Tclose(type);
    h5.string_attribute("geometry", "1280x720");
  }
  const ReadAll metavision = read_all(records);
  EXPECT_EQ(metavision.error, "");
  EXPECT_EQ(metavision.events, (std::vector<Event>{{100, 1279, 719, 1}, {250, 0, 0, -1}, {300, 70000 % 65536, 5, 1}}));
  EXPECT_EQ(metavision.sensor, (SensorSize{1280, 720}));
}

TEST(Hdf5, MissingTablesFiltersOrBytesAreClearErrors) {
  TempDir dir;
  const auto path = dir.file("odd.h5");
  std::vector<double> values(40, 1.0);
  values[0] = -5;  // an x no uint16 holds: off every sensor
  {
    Hdf5Writer h5(path);
    h5.dataset("/images", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data(), {10, 4});
  }
  try {
    read_all(path);
    ADD_FAILURE() << "no event table";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("no event table"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("odd.h5"), std::string::npos) << error.what();
  }
  const ReadAll named = read_all(path, "/images");  // any N x 4 table, by name
  ASSERT_EQ(named.events.size(), 10u);
  EXPECT_EQ(named.events[0].x, 65535);

  // A filter that is not installed (Prophesee's ECF): refused at once, saying what to install.
  const std::vector<std::uint16_t> column(100, 1);
  {
    Hdf5Writer h5(path);
    h5.group("/events");
    for (const char* name : {"/events/x", "/events/y", "/events/t", "/events/p"}) {
      h5.dataset(name, H5T_STD_U16LE, H5T_NATIVE_UINT16, column.data(), {column.size()}, 0x8ECF, H5Z_FLAG_OPTIONAL);
    }
  }
  try {
    read_all(path);
    ADD_FAILURE() << "a filter that is not installed";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("not packaged by Debian"), std::string::npos) << error.what();
  }

  // A file cut short.
  const EventBatch events = sweep_events(100'000, 1000);
  write_dsec(path, events, 0);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
  try {
    const ReadAll cut = read_all(path);
    EXPECT_LT(cut.events.size(), events.size());
    EXPECT_NE(cut.error.find("odd.h5"), std::string::npos) << cut.error;
  } catch (const std::runtime_error& error) {  // HDF5 refuses to open it: its superblock says how long it is
    EXPECT_NE(std::string(error.what()).find("odd.h5': HDF5 cannot open it: truncated file"), std::string::npos)
        << error.what();
  }
}

// ---- real recordings ------------------------------------------------------------------------------

TEST(RealRecordings, EveryFileReadsWithItsEventCountAndSensorSize) {
  const std::filesystem::path real = std::filesystem::path(EVLDT_SOURCE_DIR) / ".." / "shared" / "real";
  if (!std::filesystem::is_directory(real))
    GTEST_SKIP() << "no real recordings at " << real << " (../shared is absent)";
  struct Expected {
    const char* file;
    std::size_t events;
    SensorSize sensor;
    std::uint64_t triggers;
  };
  // Counts from the folder's README and its source projects' tests; triggers counted by evldt
  // (the arm bag holds 2078 falling and 2079 rising edges).
  for (const Expected& expected :
       {Expected{"dvxplorer_person.aedat4", 111954, {320, 240}, 0},
        Expected{"prophesee640_arm_ros2.db3", 343474, {640, 480}, 4157},
        Expected{"davis_libcaer_rollover_ros2.db3", 334331, {640, 480}, 0},
        Expected{"evt3_trigger_ros2.db3", 82469, {1280, 720}, 2}, Expected{"gen41_evt3.raw", 219596, {1280, 720}, 0},
        Expected{"gen3_spinner_evt2.raw", 539481, {640, 480}, 0}}) {
    SCOPED_TRACE(expected.file);
    const ReadAll result = read_all(real / expected.file);
    EXPECT_EQ(result.error, "");
    EXPECT_EQ(result.events.size(), expected.events);
    EXPECT_EQ(result.sensor, expected.sensor);
    EXPECT_EQ(result.counts.trigger_events, expected.triggers);
    bool in_order = true, on_sensor = true;
    for (std::size_t i = 0; i < result.events.size(); ++i) {
      in_order = in_order && (i == 0 || result.events[i].t >= result.events[i - 1].t);
      on_sensor =
          on_sensor && result.events[i].x < expected.sensor.width && result.events[i].y < expected.sensor.height;
    }
    EXPECT_TRUE(in_order);
    EXPECT_TRUE(on_sensor);
  }
}

}  // namespace
}  // namespace evldt
