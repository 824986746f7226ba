#include "client/json_writer.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace drivegate::client {
namespace {

TEST(JsonWriter, EscapesQuotesBackslashesAndControlCharacters) {
  EXPECT_EQ(JsonWriter::quote("plain"), "\"plain\"");
  EXPECT_EQ(JsonWriter::quote("say \"hi\""), "\"say \\\"hi\\\"\"");
  EXPECT_EQ(JsonWriter::quote("C:\\drive"), "\"C:\\\\drive\"");
  EXPECT_EQ(JsonWriter::quote("a\nb\tc\rd\be\ff"), "\"a\\nb\\tc\\rd\\be\\ff\"");
  EXPECT_EQ(JsonWriter::quote(std::string_view("\x01\x1f", 2)), "\"\\u0001\\u001f\"");
  EXPECT_EQ(JsonWriter::quote(std::string_view("nul\0x", 5)), "\"nul\\u0000x\"");
  EXPECT_EQ(JsonWriter::quote("Überstrom 5°"), "\"Überstrom 5°\"");  // UTF-8 passes through
  EXPECT_EQ(JsonWriter::quote("</script>"), "\"</script>\"");
}

TEST(JsonWriter, BuildsNestedObjectsWithCommas) {
  JsonWriter w;
  w.begin_object().field("axis", "x").field("ok", true).field("n", std::int64_t{-3}).key("modes").begin_array();
  w.value("pp").value("pv").end_array().key("empty").begin_array().end_array().key("o").begin_object().end_object();
  w.end_object();
  EXPECT_EQ(w.str(), R"({"axis":"x","ok":true,"n":-3,"modes":["pp","pv"],"empty":[],"o":{}})");
}

TEST(JsonWriter, NonFiniteNumbersBecomeNull) {
  JsonWriter w;
  w.begin_array()
      .value(std::numeric_limits<double>::quiet_NaN())
      .value(std::numeric_limits<double>::infinity())
      .value(0.5)
      .value(std::uint64_t{18446744073709551615ULL})
      .end_array();
  EXPECT_EQ(w.str(), "[null,null,0.5,18446744073709551615]");
}

}  // namespace
}  // namespace drivegate::client
