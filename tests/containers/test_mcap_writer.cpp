// evldt's MCAP writer, read back by evldt's MCAP reader: schemas, channels and messages in order,
// any message encoding, and a file cut short refused.

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "evldt/containers/mcap.hpp"
#include "evldt/containers/mcap_writer.hpp"
#include "evldt/events/event_decoder.hpp"
#include "support/temp_dir.hpp"

namespace evldt {
namespace {

TEST(McapWriterRoundTrip, EveryChannelReadsBackWithItsSchemaTimesAndMessages) {
  test_support::TempDir dir;
  const auto path = dir.file("out.mcap");
  {
    McapWriter mcap(path);
    const std::uint16_t json = mcap.add_schema("evldt.Test", "jsonschema", R"({"type": "object"})");
    const std::uint16_t a = mcap.add_channel(json, "/a", "json");
    const std::uint16_t b = mcap.add_channel(0, "/b", "raw");  // no schema
    mcap.write(a, 1'000'000'001, R"({"n": 1})");
    mcap.write(b, 5, std::string("\0\x01\x02", 3));
    mcap.write(a, 2'000'000'002, "");  // an empty message
    EXPECT_EQ(mcap.messages(), 3u);
    EXPECT_THROW(mcap.write(7, 0, "x"), std::invalid_argument);
    EXPECT_THROW(mcap.add_channel(9, "/c", "json"), std::invalid_argument);
    mcap.close();
  }
  const McapChannelMessages a = read_mcap_channel(path, "/a");
  EXPECT_EQ(a.schema_name, "evldt.Test");
  EXPECT_EQ(a.schema_encoding, "jsonschema");
  EXPECT_EQ(a.schema, R"({"type": "object"})");
  EXPECT_EQ(a.message_encoding, "json");
  ASSERT_EQ(a.messages.size(), 2u);
  EXPECT_EQ(a.messages[0].log_time_ns, 1'000'000'001u);
  EXPECT_EQ(a.messages[0].data, R"({"n": 1})");
  EXPECT_EQ(a.messages[1].log_time_ns, 2'000'000'002u);
  EXPECT_EQ(a.messages[1].data, "");
  const McapChannelMessages b = read_mcap_channel(path, "/b");
  EXPECT_EQ(b.schema_name, "no schema");
  ASSERT_EQ(b.messages.size(), 1u);
  EXPECT_EQ(b.messages[0].data, std::string("\0\x01\x02", 3));
  EXPECT_EQ(read_mcap_channel(path, "").topic, "/a");  // empty: the first channel

  // The last 50 bytes: the data end (13), the footer (29) and the closing magic (8). Reading stops
  // at the data end, so only a cut into it (or earlier) loses anything, and is an error.
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 40);
  EXPECT_THROW(read_mcap_channel(path, "/a"), FormatError);
}

TEST(McapWriterRoundTrip, AFileThatCannotBeCreatedIsNamed) {
  try {
    McapWriter mcap("/nonexistent-folder/out.mcap");
    FAIL() << "created a file in a missing folder";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent-folder/out.mcap"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace evldt
