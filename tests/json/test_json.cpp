#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>

#include "evldt/json/json_writer.hpp"

namespace evldt {
namespace {

TEST(JsonWriter, WritesNestedValuesWithEscaping) {
  std::ostringstream out;
  JsonWriter json(out);
  json.begin_object()
      .field("name", "a \"quoted\"\\ line\n\x01")
      .field("steps", 3)
      .field("big", std::uint64_t{18446744073709551615u})
      .field("f", 0.1)
      .field("nan", std::nan(""))
      .field("ok", true);
  json.key("list").begin_array().value(-2).value(0.5).begin_object().end_object().end_array();
  json.key("empty").begin_array().end_array();
  json.end_object();
  EXPECT_TRUE(json.done());
  EXPECT_EQ(out.str(),
            "{\n"
            "  \"name\": \"a \\\"quoted\\\"\\\\ line\\n\\u0001\",\n"
            "  \"steps\": 3,\n"
            "  \"big\": 18446744073709551615,\n"
            "  \"f\": 0.1,\n"
            "  \"nan\": null,\n"
            "  \"ok\": true,\n"
            "  \"list\": [\n"
            "    -2,\n"
            "    0.5,\n"
            "    {}\n"
            "  ],\n"
            "  \"empty\": []\n"
            "}\n");
  JsonWriter misuse(out);
  misuse.begin_object();
  EXPECT_THROW(misuse.value(1), std::logic_error);
  EXPECT_THROW(misuse.end_array(), std::logic_error);
}

TEST(JsonQuoted, EscapesQuotesBackslashesAndControlCharactersOnly) {
  EXPECT_EQ(json_quoted(""), "\"\"");
  EXPECT_EQ(json_quoted("plain text"), "\"plain text\"");
  EXPECT_EQ(json_quoted("say \"hi\" \\ there"), "\"say \\\"hi\\\" \\\\ there\"");
  EXPECT_EQ(json_quoted("a\tb\rc\nd"), "\"a\\tb\\rc\\nd\"");
  EXPECT_EQ(json_quoted(std::string_view("\x00\x1f\x7f", 3)),
            "\"\\u0000\\u001f\x7f\"");  // DEL is no control character in JSON
  EXPECT_EQ(json_quoted("\xc3\xa9t\xc3\xa9 \xe2\x86\x92"), "\"\xc3\xa9t\xc3\xa9 \xe2\x86\x92\"");  // UTF-8 unchanged
}

}  // namespace
}  // namespace evldt
