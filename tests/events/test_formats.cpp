#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_stream_reader.hpp"
#include "evldt/events/event_writer.hpp"
#include "support/temp_dir.hpp"

namespace evldt {
namespace {

namespace fs = std::filesystem;

constexpr Timestamp k2Pow24 = Timestamp{1} << 24;
constexpr Timestamp k2Pow32 = Timestamp{1} << 32;
constexpr std::size_t kOneMiB = std::size_t{1} << 20;
const SensorSize kSensor{1280, 720};

using test_support::TempDir;

std::vector<Event> events_of(const EventBatch& batch) {
  std::vector<Event> events;
  for (std::size_t i = 0; i < batch.size(); ++i) events.push_back(batch[i]);
  return events;
}

EventBatch batch_of(const std::vector<Event>& events) {
  EventBatch batch;
  for (const Event& e : events) batch.push_back(e);
  return batch;
}

/// Seeded random events in time order. Small steps (often 0) cross the 2^24 us EVT 3.0 wrap; three jumps of
/// 1.5e9 us (below the 2^31 us that dat can step) take the time past 2^32 us.
std::vector<Event> random_events(std::size_t count) {
  std::mt19937_64 random(20240611);
  std::uniform_int_distribution<int> step_us(0, 40);
  std::uniform_int_distribution<int> x(0, kSensor.width - 1);
  std::uniform_int_distribution<int> y(0, kSensor.height - 1);
  std::bernoulli_distribution on(0.5);
  std::vector<Event> events;
  Timestamp t = k2Pow24 - 3000;
  for (std::size_t i = 0; i < count; ++i) {
    if (i > 0 && i % (count / 4) == 0) t += 1'500'000'000;
    t += step_us(random);
    events.push_back({t, static_cast<std::uint16_t>(x(random)), static_cast<std::uint16_t>(y(random)),
                      on(random) ? std::int8_t{1} : std::int8_t{-1}});
  }
  return events;
}

void write_file(const fs::path& path, EventFormat format, const std::vector<Event>& events, std::size_t batches = 3) {
  EventWriter writer(path, format, kSensor);
  const std::size_t per_batch = (events.size() + batches - 1) / batches;
  for (std::size_t start = 0; start < events.size(); start += per_batch) {
    const auto end = std::min(events.size(), start + per_batch);
    writer.write(batch_of(
        {events.begin() + static_cast<std::ptrdiff_t>(start), events.begin() + static_cast<std::ptrdiff_t>(end)}));
  }
  writer.close();
}

void write_bytes(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::uint8_t> read_bytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

std::vector<std::uint8_t> bytes_of(const std::string& text) { return {text.begin(), text.end()}; }

void append_le16(std::vector<std::uint8_t>& bytes, std::uint16_t word) {
  bytes.push_back(static_cast<std::uint8_t>(word));
  bytes.push_back(static_cast<std::uint8_t>(word >> 8));
}

void append_le32(std::vector<std::uint8_t>& bytes, std::uint32_t word) {
  for (int shift = 0; shift < 32; shift += 8) bytes.push_back(static_cast<std::uint8_t>(word >> shift));
}

struct ReadResult {
  std::vector<Event> events;
  std::optional<FormatError> error;
  bool ended_after_error = false;
};

/// Reads the whole file through EventStreamReader, stopping at the first FormatError.
ReadResult read_file(const fs::path& path, std::optional<EventFormat> format, std::size_t chunk_bytes) {
  EventStreamReader reader(path, format, chunk_bytes);
  ReadResult result;
  EventBatch batch;
  try {
    while (reader.read(batch)) {
      EXPECT_FALSE(batch.empty());
      const auto events = events_of(batch);
      result.events.insert(result.events.end(), events.begin(), events.end());
    }
    EXPECT_EQ(reader.bytes_read(), reader.total_bytes());
  } catch (const FormatError& error) {
    result.error = error;
    result.ended_after_error = !reader.read(batch);
  }
  return result;
}

/// Feeds the bytes to a decoder `chunk_bytes` at a time, then finishes.
std::vector<Event> decode_in_chunks(EventFormat format, const std::vector<std::uint8_t>& bytes, std::size_t chunk_bytes,
                                    std::optional<SensorSize>* geometry = nullptr) {
  const auto decoder = make_decoder(format, "memory");
  EventBatch batch;
  for (std::size_t start = 0; start < bytes.size(); start += chunk_bytes) {
    decoder->decode(std::span(bytes).subspan(start, std::min(chunk_bytes, bytes.size() - start)), batch);
  }
  decoder->finish(batch);
  if (geometry != nullptr) *geometry = decoder->geometry();
  return events_of(batch);
}

/// Runs `decode` expecting a FormatError; returns it.
template <class Decode>
FormatError expect_format_error(Decode&& decode) {
  try {
    decode();
  } catch (const FormatError& error) {
    return error;
  }
  ADD_FAILURE() << "no FormatError";
  return FormatError("", 0, "none");
}

// ---------------------------------------------------------------------------------------------------------------
// The decoders' appender

TEST(EventBatchAppender, AppendsAfterTheEventsThereAsPushBackWouldAcrossBlocks) {
  EventBatch batch, expected;
  batch.push_back(7, 1, 2, -1);
  expected.push_back(7, 1, 2, -1);
  {
    EventBatch::Appender out(batch);
    for (int i = 0; i < 5000; ++i) {
      const Event e{i, static_cast<std::uint16_t>(i % 1280), static_cast<std::uint16_t>(i % 720),
                    i % 3 ? std::int8_t{1} : std::int8_t{-1}};
      out.push_back(e);
      expected.push_back(e);
    }
    EXPECT_EQ(out.size(), 5001u);
  }
  EXPECT_EQ(events_of(batch), events_of(expected));
  EXPECT_EQ(batch.x.size(), 5001u);
  EXPECT_EQ(batch.y.size(), 5001u);
  EXPECT_EQ(batch.p.size(), 5001u);
  { EventBatch::Appender nothing(batch); }  // appending nothing changes nothing
  EXPECT_EQ(events_of(batch), events_of(expected));
}

TEST(EventBatchAppender, AnExceptionLeavesTheEventsAppendedBeforeIt) {
  EventBatch batch;
  try {
    EventBatch::Appender out(batch);
    for (int i = 0; i < 1500; ++i) out.push_back(i, 1, 1, 1);
    throw FormatError("memory", 3, "bad");
  } catch (const FormatError&) {
  }
  ASSERT_EQ(batch.size(), 1500u);
  EXPECT_EQ(batch.x.size(), 1500u);
  EXPECT_EQ(batch.y.size(), 1500u);
  EXPECT_EQ(batch.p.size(), 1500u);
  EXPECT_EQ(batch.t.back(), 1499);
}

TEST(EventBatch, ReserveTouchedEmptiesItWithRoomThatDoesNotMove) {
  EventBatch batch;
  batch.push_back(7, 1, 2, -1);
  batch.reserve_touched(4096);
  EXPECT_TRUE(batch.empty());
  const auto* const t = batch.t.data();
  const auto* const x = batch.x.data();
  const auto* const p = batch.p.data();
  for (int i = 0; i < 4096; ++i) batch.push_back(i, 3, 4, 1);
  EXPECT_EQ(batch.t.data(), t);  // no reallocation: the room was there
  EXPECT_EQ(batch.x.data(), x);
  EXPECT_EQ(batch.p.data(), p);
  EXPECT_EQ(batch.size(), 4096u);
}

// ---------------------------------------------------------------------------------------------------------------
// Names

TEST(EventFormat, ParsesNamesAndPrintsThemBack) {
  for (const EventFormat format :
       {EventFormat::EcdText, EventFormat::Evt2, EventFormat::Evt3, EventFormat::Evt21, EventFormat::Dat}) {
    EXPECT_EQ(parse_event_format(format_name(format)), format);
  }
  EXPECT_EQ(parse_event_format("evt3"), EventFormat::Evt3);
  EXPECT_EQ(parse_event_format("ecd"), EventFormat::EcdText);
  EXPECT_FALSE(parse_event_format("evt4"));
  EXPECT_FALSE(parse_event_format(""));
}

// ---------------------------------------------------------------------------------------------------------------
// Round trips through files

struct FormatCase {
  EventFormat format;
  const char* file_name;
};

class RoundTrip : public ::testing::TestWithParam<FormatCase> {};

TEST_P(RoundTrip, ReadsBackExactlyWhatWasWrittenWhateverTheChunkSize) {
  TempDir dir;
  const auto [format, file_name] = GetParam();
  const fs::path path = dir.file(file_name);
  const std::vector<Event> written = random_events(4000);
  ASSERT_LT(written.front().t, k2Pow24);
  ASSERT_GT(written.back().t, k2Pow32);
  write_file(path, format, written);

  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, kOneMiB}) {
    SCOPED_TRACE("chunk " + std::to_string(chunk));
    EventStreamReader reader(path, std::nullopt, chunk);  // the format is guessed from the name (and header)
    EXPECT_EQ(reader.format(), format);
    if (format == EventFormat::EcdText) {
      EXPECT_FALSE(reader.geometry());
    } else {
      EXPECT_EQ(reader.geometry(), kSensor);
    }
    const ReadResult result = read_file(path, std::nullopt, chunk);
    EXPECT_FALSE(result.error) << result.error->what();
    EXPECT_EQ(result.events, written);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryFormat, RoundTrip,
                         ::testing::Values(FormatCase{EventFormat::EcdText, "events.txt"},
                                           FormatCase{EventFormat::Evt2, "events_evt2.raw"},
                                           FormatCase{EventFormat::Evt3, "events.raw"},
                                           FormatCase{EventFormat::Evt21, "events_evt21.raw"},
                                           FormatCase{EventFormat::Dat, "events.dat"}),
                         [](const auto& test_info) { return std::string(format_name(test_info.param.format)); });

TEST(RoundTripEdges, EvtFormatsCrossLongGapsAndTheirOwnWraps) {
  // Gaps of hours: EVT 3.0 steps its 24-bit time high across 512 wraps, EVT 2.0 crosses its 2^34 us wrap.
  const std::vector<Event> written{{0, 1, 2, 1},
                                   {5, 2047, 0, -1},
                                   {(Timestamp{1} << 33) + 5, 3, 4, 1},
                                   {(Timestamp{1} << 34) + 100, 5, 6, -1},
                                   {(Timestamp{1} << 34) + 100, 7, 8, 1}};
  TempDir dir;
  for (const EventFormat format : {EventFormat::Evt2, EventFormat::Evt3, EventFormat::Evt21, EventFormat::EcdText}) {
    SCOPED_TRACE(std::string(format_name(format)));
    const fs::path path = dir.file("gaps.bin");
    write_file(path, format, written);
    EXPECT_EQ(read_file(path, format, 7).events, written);
  }
}

TEST(RoundTripEdges, EmptyRecordingHasHeaderOnly) {
  TempDir dir;
  for (const EventFormat format :
       {EventFormat::Evt2, EventFormat::Evt3, EventFormat::Evt21, EventFormat::Dat, EventFormat::EcdText}) {
    SCOPED_TRACE(std::string(format_name(format)));
    const fs::path path = dir.file("empty.bin");
    write_file(path, format, {});
    const ReadResult result = read_file(path, format, 3);
    EXPECT_FALSE(result.error);
    EXPECT_TRUE(result.events.empty());
    if (format != EventFormat::EcdText) {
      EXPECT_EQ(EventStreamReader(path, format).geometry(), kSensor);
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Headers

TEST(Header, GeometryComesFromAnyOfTheHeaderForms) {
  std::optional<SensorSize> geometry;
  decode_in_chunks(EventFormat::Evt3,
                   bytes_of("% camera_integrator_name Prophesee\n% format EVT3;height=720;width=1280\n% end\n"), 5,
                   &geometry);
  EXPECT_EQ(geometry, (SensorSize{1280, 720}));

  decode_in_chunks(EventFormat::Evt2, bytes_of("% evt 2.0\r\n% geometry 640x480\r\n"), 4, &geometry);
  EXPECT_EQ(geometry, (SensorSize{640, 480}));

  auto dat = bytes_of("% Data file containing CD events\n% Version 2\n% Width 304\n% Height 240\n");
  dat.insert(dat.end(), {0x0C, 0x08});
  decode_in_chunks(EventFormat::Dat, dat, 1, &geometry);
  EXPECT_EQ(geometry, (SensorSize{304, 240}));

  decode_in_chunks(EventFormat::Evt3, bytes_of("% evt 3.0\n% end\n"), 64, &geometry);
  EXPECT_FALSE(geometry);
  decode_in_chunks(EventFormat::EcdText, bytes_of("0.5 1 2 1\n"), 64, &geometry);
  EXPECT_FALSE(geometry);
}

TEST(Header, WriterHeaderNamesEncodingAndGeometry) {
  TempDir dir;
  const fs::path path = dir.file("header.raw");
  write_file(path, EventFormat::Evt3, {});
  const auto bytes = read_bytes(path);
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()),
            "% evt 3.0\n% format EVT3;height=720;width=1280\n% geometry 1280x720\n% end\n");
}

TEST(Header, RawFileFormatIsTakenFromTheHeaderOrRefused) {
  TempDir dir;
  const fs::path path = dir.file("recording.raw");
  auto bytes = bytes_of("% format EVT2;height=480;width=640\n% end\n");
  append_le32(bytes, 0x10000000u | (3u << 11) | 4u);  // CD_ON at x=3 y=4, t=0
  write_bytes(path, bytes);
  EXPECT_EQ(EventStreamReader(path).format(), EventFormat::Evt2);
  EXPECT_EQ(read_file(path, std::nullopt, kOneMiB).events, (std::vector<Event>{{0, 3, 4, 1}}));

  write_bytes(path, bytes_of("% camera something\n% end\n"));
  const FormatError no_version = expect_format_error([&] { EventStreamReader reader(path); });
  EXPECT_EQ(no_version.byte_offset(), 0u);
  EXPECT_NE(std::string(no_version.what()).find(path.string()), std::string::npos);

  write_bytes(path, bytes_of("% format EVT4;height=480;width=640\n% end\n"));
  EXPECT_THROW(EventStreamReader reader(path), FormatError);
}

TEST(Header, DecoderRefusesDataTheHeaderSaysIsAnotherEncoding) {
  const FormatError error =
      expect_format_error([] { decode_in_chunks(EventFormat::Evt3, bytes_of("% evt 2.0\n% end\n"), 64); });
  EXPECT_NE(std::string(error.what()).find("EVT2"), std::string::npos);
}

TEST(Header, UnterminatedHeaderLineIsTruncation) {
  const auto bytes = bytes_of("% evt 3.0\n% format EVT3;hei");
  const FormatError error = expect_format_error([&] { decode_in_chunks(EventFormat::Evt3, bytes, 4); });
  EXPECT_EQ(error.byte_offset(), 10u);
}

// ---------------------------------------------------------------------------------------------------------------
// Hand-written EVT 2.0 / EVT 3.0 words

TEST(Evt2, DecodesHandWrittenWords) {
  auto bytes = bytes_of("% evt 2.0\n% end\n");
  append_le32(bytes, (0x1u << 28) | (5u << 22) | (100u << 11) | 200u);  // CD_ON before any TIME_HIGH: time high 0
  append_le32(bytes, (0x8u << 28) | 3u);                                // TIME_HIGH: time 3 * 64
  append_le32(bytes, (0x0u << 28) | (7u << 22) | (1u << 11) | 2u);      // CD_OFF
  append_le32(bytes, (0xAu << 28) | 0x12345u);                          // EXT_TRIGGER: skipped
  append_le32(bytes, (0xEu << 28) | 0x1u);                              // OTHERS: skipped
  append_le32(bytes, (0xFu << 28) | 0x7u);                              // CONTINUED: skipped
  append_le32(bytes, (0x8u << 28) | 0x0FFFFFFFu);                       // last TIME_HIGH before the 2^34 us wrap
  append_le32(bytes, (0x1u << 28) | (63u << 22) | (2047u << 11) | 2047u);
  append_le32(bytes, (0x8u << 28) | 1u);  // wrapped
  append_le32(bytes, (0x0u << 28) | (9u << 22) | (10u << 11) | 11u);
  const std::vector<Event> expected{{5, 100, 200, 1},
                                    {3 * 64 + 7, 1, 2, -1},
                                    {Timestamp{0x0FFFFFFF} * 64 + 63, 2047, 2047, 1},
                                    {((Timestamp{1} << 28) + 1) * 64 + 9, 10, 11, -1}};
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{3}, bytes.size()}) {
    EXPECT_EQ(decode_in_chunks(EventFormat::Evt2, bytes, chunk), expected) << "chunk " << chunk;
  }
}

TEST(Evt3, DecodesHandWrittenWordsWithVectorsAndTimeWrap) {
  std::vector<std::uint8_t> bytes;  // no header: the data may start right away
  append_le16(bytes, 0x2805);       // EVT_ADDR_X before any time: dropped
  append_le16(bytes, 0x8001);       // TIME_HIGH 1 -> 4096 us
  append_le16(bytes, 0x6010);       // TIME_LOW 16 -> 4112 us
  append_le16(bytes, 0x000A);       // EVT_ADDR_Y 10
  append_le16(bytes, 0x2805);       // EVT_ADDR_X polarity 1, x 5
  append_le16(bytes, 0x3064);       // VECT_BASE_X polarity 0, x 100
  append_le16(bytes, 0x4805);       // VECT_12 bits 0, 2, 11 -> x 100, 102, 111; base -> 112
  append_le16(bytes, 0x5081);       // VECT_8 bits 0, 7 -> x 112, 119; base -> 120
  append_le16(bytes, 0x7123);       // CONTINUED_4, EXT_TRIGGER, OTHERS, CONTINUED_12: skipped
  append_le16(bytes, 0xA001);
  append_le16(bytes, 0xE014);
  append_le16(bytes, 0xF456);
  append_le16(bytes, 0x5002);  // VECT_8 bit 1 -> x 121
  append_le16(bytes, 0x8FFF);  // TIME_HIGH 0xFFF
  append_le16(bytes, 0x6005);  // TIME_LOW 5
  append_le16(bytes, 0x2007);  // EVT_ADDR_X polarity 0, x 7
  append_le16(bytes, 0x8002);  // TIME_HIGH 2: went back, so the 24-bit time base wrapped
  append_le16(bytes, 0x6003);  // TIME_LOW 3
  append_le16(bytes, 0x0014);  // EVT_ADDR_Y 20
  append_le16(bytes, 0x2801);  // EVT_ADDR_X polarity 1, x 1
  const Timestamp before_wrap = (Timestamp{0xFFF} << 12) + 5;
  const Timestamp after_wrap = k2Pow24 + (Timestamp{2} << 12) + 3;
  const std::vector<Event> expected{{4112, 5, 10, 1},    {4112, 100, 10, -1},      {4112, 102, 10, -1},
                                    {4112, 111, 10, -1}, {4112, 112, 10, -1},      {4112, 119, 10, -1},
                                    {4112, 121, 10, -1}, {before_wrap, 7, 10, -1}, {after_wrap, 1, 20, 1}};
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{3}, bytes.size()}) {
    EXPECT_EQ(decode_in_chunks(EventFormat::Evt3, bytes, chunk), expected) << "chunk " << chunk;
  }
}

// ---------------------------------------------------------------------------------------------------------------
// ECD text

TEST(EcdText, ConvertsDecimalSecondsToExactMicroseconds) {
  const std::string text =
      "# t x y p\n"
      "0.0000015 1 2 1\n"  // 1.5 us rounds half up
      "0.0000014999 1 2 1\r\n"
      "\n"
      "12.5 3 4 0\n"
      "1 0 0 1\n"
      "0.003811000 5 6 0\n"
      "0.9999995 7 8 1\n"  // the rounding carries into the seconds
      "   \t\n"
      "4294.967296123 65535 65535 0\n"
      "  3.5 11 12 1 \t\n"         // blanks before and after
      "3.6 0000000000013 007 0\n"  // leading zeros, past the plain line's nine digits
      "2.000001\t9  10 1";         // last line without '\n'
  const std::vector<Event> expected{{2, 1, 2, 1},
                                    {1, 1, 2, 1},
                                    {12'500'000, 3, 4, -1},
                                    {1'000'000, 0, 0, 1},
                                    {3811, 5, 6, -1},
                                    {1'000'000, 7, 8, 1},
                                    {4'294'967'296, 65535, 65535, -1},
                                    {3'500'000, 11, 12, 1},
                                    {3'600'000, 13, 7, -1},
                                    {2'000'001, 9, 10, 1}};
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, text.size()}) {
    EXPECT_EQ(decode_in_chunks(EventFormat::EcdText, bytes_of(text), chunk), expected) << "chunk " << chunk;
  }
}

TEST(EcdText, WriterPrintsSecondsWithNineFractionDigits) {
  TempDir dir;
  const fs::path path = dir.file("events.txt");
  write_file(path, EventFormat::EcdText, {{3811, 5, 6, -1}, {12'500'000, 640, 480, 1}, {k2Pow32, 0, 0, 1}}, 1);
  const auto bytes = read_bytes(path);
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()),
            "0.003811000 5 6 0\n12.500000000 640 480 1\n4294.967296000 0 0 1\n");
}

TEST(EcdText, MalformedLinesAreReportedAtTheirStartWithTheirNumber) {
  const std::string good = "0.1 1 2 1\n";  // 10 bytes
  for (const std::string bad :
       {"0.2 abc 3 0", "0.2 1 2", "0.2 1 2 2", "0.2 -1 2 1", "0.2 1 65536 1", "0.2 1 2 1 junk", "-0.2 1 2 1",
        "0.2e3 1 2 1", "0.2. 1 2 1", ". 1 2 1", "0,2 1 2 1", "0.2 1 2 10", "0.2 1 2 1x", "0.2 1 2 +1", "0.2 1 2 1 0",
        "0.2 1 0065536 1", "0. 1 2 1", "1234567890123 1 2 1", "88888888888888888888888888.5 1 2 1"}) {
    SCOPED_TRACE(bad);
    EventBatch batch;
    const auto decoder = make_decoder(EventFormat::EcdText, "events.txt");
    const FormatError error =
        expect_format_error([&] { decoder->decode(bytes_of(good + bad + "\n0.3 1 1 1\n"), batch); });
    EXPECT_EQ(events_of(batch), (std::vector<Event>{{100000, 1, 2, 1}}));
    EXPECT_EQ(error.byte_offset(), good.size());
    EXPECT_NE(std::string(error.what()).find("line 2"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("events.txt"), std::string::npos) << error.what();
  }
}

TEST(EcdText, GarbageLineInAFileDeliversTheEventsBeforeIt) {
  TempDir dir;
  const fs::path path = dir.file("garbage.txt");
  write_bytes(path, bytes_of("0.1 1 2 1\n0.2 3 4 0\n\x01\x02garbage\n0.3 5 6 1\n"));
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, kOneMiB}) {
    const ReadResult result = read_file(path, std::nullopt, chunk);
    EXPECT_EQ(result.events, (std::vector<Event>{{100000, 1, 2, 1}, {200000, 3, 4, -1}}));
    ASSERT_TRUE(result.error);
    EXPECT_EQ(result.error->byte_offset(), 20u);
    EXPECT_NE(std::string(result.error->what()).find("line 3"), std::string::npos);
    EXPECT_TRUE(result.ended_after_error);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Corrupt and truncated files

class Truncated : public ::testing::TestWithParam<FormatCase> {};

TEST_P(Truncated, DeliversEveryEventBeforeTheCutThenReportsItsOffset) {
  TempDir dir;
  const auto [format, file_name] = GetParam();
  const fs::path path = dir.file(file_name);
  const std::vector<Event> written = random_events(400);
  write_file(path, format, written);
  auto bytes = read_bytes(path);

  // Cut the file inside its last record / word / line: that last event is lost, and the error points at
  // where the partial data starts.
  std::uint64_t partial_start = 0;
  switch (format) {
    case EventFormat::EcdText:
      partial_start = std::string(bytes.begin(), bytes.end()).rfind('\n', bytes.size() - 2) + 1;
      bytes.resize(bytes.size() - 3);  // drops " p\n": the line ends after y
      break;
    case EventFormat::Evt2:
      partial_start = bytes.size() - 4;
      bytes.resize(bytes.size() - 1);
      break;
    case EventFormat::Evt3:
      partial_start = bytes.size() - 2;
      bytes.resize(bytes.size() - 1);
      break;
    case EventFormat::Evt21:
      partial_start = bytes.size() - 8;
      bytes.resize(bytes.size() - 3);
      break;
    case EventFormat::Dat:
      partial_start = bytes.size() - 8;
      bytes.resize(bytes.size() - 5);
      break;
    case EventFormat::Aedat2:
    case EventFormat::Aedat31:
    case EventFormat::Aedat31Network:
    case EventFormat::EventStream:
      FAIL() << "evldt does not write " << format_name(format);
  }
  write_bytes(path, bytes);
  const std::vector<Event> before_cut(written.begin(), written.end() - 1);

  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, kOneMiB}) {
    SCOPED_TRACE("chunk " + std::to_string(chunk));
    const ReadResult result = read_file(path, std::nullopt, chunk);
    EXPECT_EQ(result.events, before_cut);
    ASSERT_TRUE(result.error);
    EXPECT_EQ(result.error->byte_offset(), partial_start);
    EXPECT_EQ(result.error->source(), path.string());
    EXPECT_NE(std::string(result.error->what()).find(path.string()), std::string::npos) << result.error->what();
    EXPECT_TRUE(result.ended_after_error);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryFormat, Truncated,
                         ::testing::Values(FormatCase{EventFormat::EcdText, "events.txt"},
                                           FormatCase{EventFormat::Evt2, "events_evt2.raw"},
                                           FormatCase{EventFormat::Evt3, "events.raw"},
                                           FormatCase{EventFormat::Evt21, "events_evt21.raw"},
                                           FormatCase{EventFormat::Dat, "events.dat"}),
                         [](const auto& test_info) { return std::string(format_name(test_info.param.format)); });

TEST(Corrupt, DatCutInTheMiddleKeepsTheWholeRecordsBeforeIt) {
  TempDir dir;
  const fs::path path = dir.file("cut.dat");
  const std::vector<Event> written = random_events(100);
  write_file(path, EventFormat::Dat, written);
  auto bytes = read_bytes(path);
  const std::size_t data_start = bytes.size() - 8 * written.size();
  bytes.resize(data_start + 8 * 37 + 3);
  write_bytes(path, bytes);

  const ReadResult result = read_file(path, std::nullopt, 7);
  EXPECT_EQ(result.events, std::vector<Event>(written.begin(), written.begin() + 37));
  ASSERT_TRUE(result.error);
  EXPECT_EQ(result.error->byte_offset(), data_start + 8 * 37);
}

// Reserved word types are skipped and counted, as the vendor SDK skips them: some cameras pad their
// streams with them, and no single word can stop a stream.
TEST(RawQuirks, ReservedEvt2TypesAreSkippedAndCountedTriggersCounted) {
  auto bytes = bytes_of("% evt 2.0\n% end\n");
  append_le32(bytes, (0x1u << 28) | (1u << 11) | 1u);
  append_le32(bytes, 0x20000000u);  // type 0x2 is reserved
  append_le32(bytes, 0xA0000001u);  // an external trigger
  append_le32(bytes, 0xD1234567u);  // type 0xD is reserved
  append_le32(bytes, (0x1u << 28) | (2u << 11) | 2u);
  EventBatch batch;
  const auto decoder = make_decoder(EventFormat::Evt2, "cam.raw");
  decoder->decode(bytes, batch);
  decoder->finish(batch);
  EXPECT_EQ(events_of(batch), (std::vector<Event>{{0, 1, 1, 1}, {0, 2, 2, 1}}));
  EXPECT_EQ(decoder->counts(), (DecodeCounts{2, 1}));
}

TEST(RawQuirks, Evt3PaddingAndReservedWordsAreSkippedAndCountedInAnyChunking) {
  TempDir dir;
  const fs::path path = dir.file("padded.raw");
  auto bytes = bytes_of("% evt 3.0\n% end\n");
  // TIME_HIGH 0, y 3, x 4, then IMX636-style 0x9999 padding and the other reserved types, a
  // trigger, and x 5.
  for (const std::uint16_t word : std::initializer_list<std::uint16_t>{0x8000, 0x0003, 0x2804, 0x9999, 0x9999, 0x1000,
                                                                       0xB000, 0xC000, 0xD000, 0xA001, 0x2805}) {
    append_le16(bytes, word);
  }
  write_bytes(path, bytes);
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{3}, kOneMiB}) {
    SCOPED_TRACE(chunk);
    EventStreamReader reader(path, std::nullopt, chunk);
    EventBatch batch, all;
    while (reader.read(batch)) {
      for (std::size_t i = 0; i < batch.size(); ++i) all.push_back(batch[i]);
    }
    EXPECT_EQ(events_of(all), (std::vector<Event>{{0, 4, 3, 1}, {0, 5, 3, 1}}));
    EXPECT_EQ(reader.counts(), (DecodeCounts{6, 1}));
  }
}

// EVT 2.1 from its description: a vector word sets up to 32 events; the two 32-bit halves come in
// the order the header names, or (without one) the order of the camera's system id.
TEST(RawQuirks, Evt21VectorsInEitherHalfOrder) {
  const std::uint64_t time_high = std::uint64_t{0x8} << 60 | std::uint64_t{1} << 32;  // time bits 6.. = 1: 64 us
  const std::uint64_t vector =
      std::uint64_t{0x1} << 60 | std::uint64_t{5} << 54 | std::uint64_t{32} << 43 | std::uint64_t{7} << 32 | 0b1011u;
  const std::uint64_t before_time = std::uint64_t{0x0} << 60 | std::uint64_t{3} << 32 | 1u;  // no time yet: dropped
  const std::uint64_t reserved = std::uint64_t{0x3} << 60, trigger = std::uint64_t{0xA} << 60 | std::uint64_t{1} << 32;
  const std::vector<Event> expected{{69, 32, 7, 1}, {69, 33, 7, 1}, {69, 35, 7, 1}};
  for (const auto& [header, legacy] :
       {std::pair{"% evt 2.1\n% system_ID 49\n% end\n", true},
        std::pair{"% format EVT21;endianness=little;height=720;width=1280\n% end\n", false},
        std::pair{"% format EVT21;endianness=legacy\n% end\n", true},
        std::pair{"% format EVT21;height=320;width=320\n% end\n", false}}) {
    SCOPED_TRACE(header);
    auto bytes = bytes_of(header);
    for (const std::uint64_t word : {before_time, time_high, reserved, vector, trigger}) {
      const auto high = static_cast<std::uint32_t>(word >> 32), low = static_cast<std::uint32_t>(word);
      append_le32(bytes, legacy ? high : low);
      append_le32(bytes, legacy ? low : high);
    }
    EventBatch batch;
    const auto decoder = make_decoder(EventFormat::Evt21, "cam.raw");
    decoder->decode(bytes, batch);
    decoder->finish(batch);
    EXPECT_EQ(events_of(batch), expected);
    EXPECT_EQ(decoder->counts(), (DecodeCounts{1, 1}));
  }
}

// ---------------------------------------------------------------------------------------------------------------
// AEDAT 2.0 and 3.1, from iniVation's and jAER's format descriptions

void append_be32(std::vector<std::uint8_t>& bytes, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) bytes.push_back(static_cast<std::uint8_t>(value >> shift));
}

/// A 28-byte AEDAT 3.1 packet header: type, source 1, event size, timestamp offset 4, overflow,
/// capacity = number = valid = count.
void append_aedat3_packet_header(std::vector<std::uint8_t>& bytes, std::uint16_t type, std::uint32_t event_size,
                                 std::uint32_t overflow, std::uint32_t count) {
  append_le16(bytes, type);
  append_le16(bytes, 1);
  for (const std::uint32_t value : {event_size, 4u, overflow, count, count, count}) append_le32(bytes, value);
}

void append_polarity(std::vector<std::uint8_t>& bytes, std::uint32_t x, std::uint32_t y, bool on, std::uint32_t t,
                     bool valid = true) {
  append_le32(bytes, x << 17 | y << 2 | (on ? 2u : 0u) | (valid ? 1u : 0u));
  append_le32(bytes, t);
}

TEST(Aedat, Aedat31PolarityPacketsWithTheirOverflowOtherPacketsSkipped) {
  TempDir dir;
  const fs::path path = dir.file("davis.aedat");
  auto bytes = bytes_of(
      "#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS346B\r\n#Start-Time: 2017-06-07 10:00:00 (TZ+0200)\r\n"
      "#!END-HEADER\r\n");
  append_aedat3_packet_header(bytes, 1, 8, 0, 3);
  append_polarity(bytes, 5, 7, true, 100);
  append_polarity(bytes, 6, 7, true, 150, /*valid=*/false);
  append_polarity(bytes, 345, 259, false, 200);
  append_aedat3_packet_header(bytes, 2, 10, 0, 2);  // a frame packet: 20 bytes, skipped
  bytes.insert(bytes.end(), 20, 0x23);
  const std::size_t third_packet = bytes.size();
  append_aedat3_packet_header(bytes, 1, 8, 1, 1);  // time overflowed once
  append_polarity(bytes, 1, 2, true, 5);
  write_bytes(path, bytes);
  const std::vector<Event> expected{{100, 5, 7, 1}, {200, 345, 259, -1}, {(Timestamp{1} << 31) + 5, 1, 2, 1}};
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, kOneMiB}) {
    SCOPED_TRACE(chunk);
    const ReadResult result = read_file(path, std::nullopt, chunk);  // recognised by its first line
    EXPECT_FALSE(result.error);
    EXPECT_EQ(result.events, expected);
    EventStreamReader reader(path, std::nullopt, chunk);
    EXPECT_EQ(reader.format(), EventFormat::Aedat31);
    EXPECT_EQ(reader.geometry(), (SensorSize{346, 260}));
    EventBatch batch;
    while (reader.read(batch)) {
    }
    EXPECT_EQ(reader.counts().skipped_words, 2u);  // the invalid event and the frame packet
  }
  bytes.resize(third_packet + 30);  // cut inside the last packet
  write_bytes(path, bytes);
  const ReadResult cut = read_file(path, std::nullopt, 7);
  EXPECT_EQ(cut.events, std::vector<Event>(expected.begin(), expected.begin() + 2));
  ASSERT_TRUE(cut.error);
  EXPECT_EQ(cut.error->byte_offset(), third_packet);
}

/// libcaer's 20-byte network header (network.h): magic, sequence number, version 1, format, source id.
void append_aedat3_network_header(std::vector<std::uint8_t>& bytes, std::uint8_t version = 1) {
  constexpr std::uint64_t kMagic = 0x1D378BC90B9A6658;
  append_le32(bytes, static_cast<std::uint32_t>(kMagic));
  append_le32(bytes, static_cast<std::uint32_t>(kMagic >> 32));
  append_le32(bytes, 0);  // sequence number
  append_le32(bytes, 0);
  bytes.push_back(version);
  bytes.push_back(0);     // format
  append_le16(bytes, 1);  // source id
}

TEST(Aedat, Aedat31NetworkStreamIsRecognisedByItsMagicAndDecodedAsTheFilesPackets) {
  TempDir dir;
  const fs::path path = dir.file("stream.bin");  // a name that tells nothing
  std::vector<std::uint8_t> bytes;
  append_aedat3_network_header(bytes);
  append_aedat3_packet_header(bytes, 1, 8, 0, 2);
  append_polarity(bytes, 5, 7, true, 100);
  append_polarity(bytes, 300, 200, false, 200);
  append_aedat3_packet_header(bytes, 2, 10, 0, 1);  // another type, skipped
  bytes.insert(bytes.end(), 10, 0x23);
  append_aedat3_packet_header(bytes, 1, 8, 1, 1);
  append_polarity(bytes, 1, 2, true, 5);
  write_bytes(path, bytes);
  const std::vector<Event> expected{{100, 5, 7, 1}, {200, 300, 200, -1}, {(Timestamp{1} << 31) + 5, 1, 2, 1}};
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, kOneMiB}) {
    SCOPED_TRACE(chunk);
    const ReadResult result = read_file(path, std::nullopt, chunk);
    EXPECT_FALSE(result.error);
    EXPECT_EQ(result.events, expected);
    EventStreamReader reader(path, std::nullopt, chunk);
    EXPECT_EQ(reader.format(), EventFormat::Aedat31Network);
    EXPECT_FALSE(reader.geometry());  // the stream names no sensor size
  }
  // A wrong version, and a stream cut inside its network header, say so.
  std::vector<std::uint8_t> version_two;
  append_aedat3_network_header(version_two, 2);
  write_bytes(path, version_two);
  const ReadResult wrong = read_file(path, EventFormat::Aedat31Network, 7);
  ASSERT_TRUE(wrong.error);
  EXPECT_NE(std::string(wrong.error->what()).find("version 2"), std::string::npos) << wrong.error->what();
  bytes.resize(12);
  write_bytes(path, bytes);
  const ReadResult cut = read_file(path, EventFormat::Aedat31Network, 7);
  ASSERT_TRUE(cut.error);
  EXPECT_NE(std::string(cut.error->what()).find("network header"), std::string::npos) << cut.error->what();
}

TEST(Aedat, Aedat2AddressesOfDavisAndDvs128ChipsMirroredToATopLeftOrigin) {
  TempDir dir;
  const fs::path path = dir.file("rec.aedat");
  auto davis = bytes_of(
      "#!AER-DAT2.0\r\n# This is a raw AE data file\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n"
      "#End Of ASCII Header\r\n");
  auto record = [](std::vector<std::uint8_t>& bytes, std::uint32_t address, std::uint32_t t) {
    append_be32(bytes, address);
    append_be32(bytes, t);
  };
  record(davis, 20u << 22 | 10u << 12 | 1u << 11, 0xFFFFFFF0u);  // ON at raw (10, 20)
  record(davis, 0x80000000u | 5u << 12, 0xFFFFFFF1u);            // an APS sample: skipped
  record(davis, 1u << 10, 0xFFFFFFF2u);                          // an external input: a trigger
  record(davis, 0u << 22 | 239u << 12, 0x10u);                   // OFF at raw (239, 0), after the 2^32 us wrap
  write_bytes(path, davis);
  EventStreamReader reader(path, std::nullopt, 5);
  EXPECT_EQ(reader.format(), EventFormat::Aedat2);
  EXPECT_EQ(reader.geometry(), (SensorSize{240, 180}));
  EXPECT_EQ(read_file(path, std::nullopt, 5).events,
            (std::vector<Event>{{0xFFFFFFF0, 229, 159, 1}, {(Timestamp{1} << 32) + 0x10, 0, 179, -1}}));
  EventBatch batch;
  while (reader.read(batch)) {
  }
  EXPECT_EQ(reader.counts(), (DecodeCounts{1, 1}));

  auto dvs128 = bytes_of("#!AER-DAT2.0\r\n# created 2008\r\n");  // no chip line: a DVS128
  record(dvs128, 4u << 8 | 3u << 1 | 0u, 7);                     // raw (3, 4), polarity bit 0: ON
  record(dvs128, 0x8000u, 8);                                    // an external event
  record(dvs128, 127u << 8 | 0u << 1 | 1u, 9);
  write_bytes(path, dvs128);
  EXPECT_EQ(EventStreamReader(path).geometry(), (SensorSize{128, 128}));
  EXPECT_EQ(read_file(path, std::nullopt, kOneMiB).events, (std::vector<Event>{{7, 124, 123, 1}, {9, 127, 0, -1}}));
}

// Event Stream 2.x, from its description: time deltas in a byte, overflow bytes, x and y; the origin
// is the bottom left.
TEST(EventStream, DvsAndAtisEventsWithTheirTimeDeltas) {
  TempDir dir;
  const fs::path path = dir.file("rec.es");
  auto header = [](std::uint8_t type) {
    auto bytes = bytes_of("Event Stream");
    bytes.insert(bytes.end(), {2, 0, 0, type});
    append_le16(bytes, 304);
    append_le16(bytes, 240);
    return bytes;
  };
  auto coordinates = [](std::vector<std::uint8_t>& bytes, std::uint16_t x, std::uint16_t y) {
    append_le16(bytes, x);
    append_le16(bytes, y);
  };
  auto dvs = header(1);
  dvs.push_back(0xFF);         // t += 127
  dvs.push_back(10 << 1 | 1);  // t += 10: ON
  coordinates(dvs, 3, 0);      // bottom row
  dvs.push_back(0xFE);         // reset: nothing
  dvs.push_back(0 << 1 | 0);   // same time, OFF
  coordinates(dvs, 303, 239);
  write_bytes(path, dvs);
  EXPECT_EQ(EventStreamReader(path, std::nullopt, 3).format(), EventFormat::EventStream);
  EXPECT_EQ(EventStreamReader(path, std::nullopt, 3).geometry(), (SensorSize{304, 240}));
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{5}, kOneMiB}) {
    EXPECT_EQ(read_file(path, std::nullopt, chunk).events, (std::vector<Event>{{137, 3, 239, 1}, {137, 303, 0, -1}}));
  }

  auto atis = header(2);
  atis.push_back(0xFE);        // t += 63 * 2
  atis.push_back(5 << 2 | 2);  // t += 5: a change detection, ON
  coordinates(atis, 7, 8);
  atis.push_back(1 << 2 | 1);  // t += 1: a threshold crossing, skipped
  coordinates(atis, 7, 8);
  write_bytes(path, atis);
  EXPECT_EQ(read_file(path, std::nullopt, 2).events, (std::vector<Event>{{131, 7, 231, 1}}));

  atis.resize(atis.size() - 2);  // cut inside the last event
  write_bytes(path, atis);
  const ReadResult cut = read_file(path, std::nullopt, 4);
  ASSERT_TRUE(cut.error);
  EXPECT_EQ(cut.error->byte_offset(), atis.size() - 3);
}

TEST(RawQuirks, BareWordsHaveNoHeaderEvenWhenTheyStartWithAPercentByte) {
  // 0x0025 is EVT_ADDR_Y 37, whose first byte is '%'.
  std::vector<std::uint8_t> bytes;
  for (const std::uint16_t word : std::initializer_list<std::uint16_t>{0x8000, 0x0025, 0x2804})
    append_le16(bytes, word);
  bytes.insert(bytes.begin(), {0x25, 0x00});  // y = 37 first
  EventBatch batch;
  const auto decoder = detail::make_evt3_decoder("packet", RawFraming::BareWords);
  decoder->decode(bytes, batch);
  decoder->finish(batch);
  EXPECT_EQ(events_of(batch), (std::vector<Event>{{0, 4, 37, 1}}));
}

TEST(Corrupt, DatWithWrongEventSizeOrTypeIsRefused) {
  TempDir dir;
  const fs::path path = dir.file("wrong.dat");
  const std::string header = "% Version 2\n% Width 640\n% Height 480\n";
  auto bytes = bytes_of(header);
  bytes.insert(bytes.end(), {0x0C, 0x10});
  append_le32(bytes, 10);
  append_le32(bytes, 1);
  write_bytes(path, bytes);
  const ReadResult wrong_size = read_file(path, std::nullopt, kOneMiB);
  EXPECT_TRUE(wrong_size.events.empty());
  ASSERT_TRUE(wrong_size.error);
  EXPECT_EQ(wrong_size.error->byte_offset(), header.size() + 1);
  EXPECT_NE(std::string(wrong_size.error->what()).find("event size"), std::string::npos);

  bytes[header.size()] = 0x0E;  // external triggers, not CD events
  bytes[header.size() + 1] = 8;
  write_bytes(path, bytes);
  const ReadResult wrong_type = read_file(path, std::nullopt, kOneMiB);
  ASSERT_TRUE(wrong_type.error);
  EXPECT_EQ(wrong_type.error->byte_offset(), header.size());
}

TEST(Corrupt, DatTimesUnwrapPast32Bits) {
  auto bytes = bytes_of("% Width 640\n% Height 480\n");
  bytes.insert(bytes.end(), {0x0C, 0x08});
  for (const std::uint32_t t : {0xFFFFFFF0u, 0x00000010u, 0x7FFFFFFFu}) {
    append_le32(bytes, t);
    append_le32(bytes, 1u | (2u << 14) | (1u << 28));
  }
  const std::vector<Event> expected{{0xFFFFFFF0, 1, 2, 1}, {k2Pow32 + 0x10, 1, 2, 1}, {k2Pow32 + 0x7FFFFFFF, 1, 2, 1}};
  EXPECT_EQ(decode_in_chunks(EventFormat::Dat, bytes, 5), expected);
}

// ---------------------------------------------------------------------------------------------------------------
// Opening and writing

TEST(Reader, MissingFileIsARuntimeErrorNamingThePath) {
  TempDir dir;
  const fs::path path = dir.file("does-not-exist.raw");
  try {
    EventStreamReader reader(path);
    FAIL() << "opened a missing file";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
  }
}

TEST(Reader, UnknownExtensionNeedsAnExplicitFormat) {
  TempDir dir;
  const fs::path path = dir.file("events.bin");
  write_file(path, EventFormat::Dat, {{1, 2, 3, 1}});
  EXPECT_THROW(EventStreamReader reader(path), std::runtime_error);
  EXPECT_EQ(read_file(path, EventFormat::Dat, kOneMiB).events, (std::vector<Event>{{1, 2, 3, 1}}));
}

TEST(Writer, RejectsTimeGoingBackwardsAndKeepsWhatWasWritten) {
  TempDir dir;
  for (const EventFormat format :
       {EventFormat::EcdText, EventFormat::Evt2, EventFormat::Evt3, EventFormat::Evt21, EventFormat::Dat}) {
    SCOPED_TRACE(std::string(format_name(format)));
    const fs::path path = dir.file("backwards.bin");
    EventWriter writer(path, format, kSensor);
    writer.write(batch_of({{100, 1, 1, 1}, {100, 2, 2, -1}}));
    EXPECT_THROW(writer.write(batch_of({{150, 1, 1, 1}, {120, 1, 1, 1}})), std::invalid_argument);  // within a batch
    EXPECT_THROW(writer.write(batch_of({{99, 1, 1, 1}})), std::invalid_argument);                   // across batches
    EXPECT_THROW(writer.write(batch_of({{-1, 1, 1, 1}})), std::invalid_argument);
    writer.write(batch_of({{101, 3, 3, 1}}));
    writer.close();
    EXPECT_EQ(read_file(path, format, kOneMiB).events,
              (std::vector<Event>{{100, 1, 1, 1}, {100, 2, 2, -1}, {101, 3, 3, 1}}));
  }
}

TEST(Writer, RejectsWhatTheFormatCannotHold) {
  TempDir dir;
  const fs::path path = dir.file("limits.bin");
  EXPECT_THROW(EventWriter(path, EventFormat::Evt3, SensorSize{4096, 64}), std::invalid_argument);
  EventWriter evt3(path, EventFormat::Evt3, SensorSize{2048, 2048});
  EXPECT_THROW(evt3.write(batch_of({{1, 2048, 0, 1}})), std::invalid_argument);
  EventWriter dat(path, EventFormat::Dat, kSensor);
  EXPECT_THROW(dat.write(batch_of({{0, 1, 1, 1}, {Timestamp{1} << 31, 1, 1, 1}})), std::invalid_argument);
}

TEST(Writer, UnwritablePathIsARuntimeErrorNamingIt) {
  TempDir dir;
  const fs::path path = dir.file("no-such-dir") / "events.raw";
  try {
    EventWriter writer(path, EventFormat::Evt3, kSensor);
    FAIL() << "created a file in a missing directory";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace evldt
