#include <gtest/gtest.h>

#include <cmath>

#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {
namespace {

using namespace std::chrono_literals;

TEST(Scalars, DurationsWithUnits) {
  EXPECT_EQ(parse_duration("250us"), core::Duration{250us});
  EXPECT_EQ(parse_duration("1ms"), core::Duration{1ms});
  EXPECT_EQ(parse_duration("0.5s"), core::Duration{500ms});
  EXPECT_EQ(parse_duration("2s"), core::Duration{2s});
  EXPECT_EQ(parse_duration("2"), core::Duration{2s});  // a bare number is seconds
  EXPECT_EQ(parse_duration("1.5min"), core::Duration{90s});
  EXPECT_EQ(parse_duration("100ns"), core::Duration{100ns});
  EXPECT_EQ(parse_duration("-1ms"), core::Duration{-1ms});  // parses; range checks refuse it later
}

TEST(Scalars, DurationsRejected) {
  EXPECT_FALSE(parse_duration("fast"));
  EXPECT_FALSE(parse_duration("ms"));
  EXPECT_FALSE(parse_duration("1 hour"));
  EXPECT_FALSE(parse_duration(".inf"));
  EXPECT_FALSE(parse_duration(".nan s"));
  EXPECT_FALSE(parse_duration("1e30s"));  // would overflow nanoseconds
  EXPECT_FALSE(parse_duration(""));
}

TEST(Scalars, FormatDuration) {
  EXPECT_EQ(format_duration(1ms), "1ms");
  EXPECT_EQ(format_duration(250us), "250us");
  EXPECT_EQ(format_duration(30s), "30s");
  EXPECT_EQ(format_duration(1500ms), "1500ms");
}

TEST(Scalars, Numbers) {
  EXPECT_EQ(parse_number("5"), 5.0);
  EXPECT_EQ(parse_number("-2.5"), -2.5);
  EXPECT_EQ(parse_number("+1e3"), 1000.0);
  EXPECT_EQ(parse_number(".5"), 0.5);
  EXPECT_EQ(parse_number("0x10"), 16.0);
  EXPECT_TRUE(std::isinf(*parse_number(".inf")));
  EXPECT_TRUE(std::isinf(*parse_number("-.Inf")));
  EXPECT_TRUE(std::isnan(*parse_number(".nan")));
  EXPECT_FALSE(parse_number("inf"));
  EXPECT_FALSE(parse_number("nan"));
  EXPECT_FALSE(parse_number("fast"));
  EXPECT_FALSE(parse_number("1.2.3"));
  EXPECT_FALSE(parse_number("--1"));
  EXPECT_FALSE(parse_number(""));
}

TEST(Scalars, Integers) {
  EXPECT_EQ(parse_integer("42"), 42);
  EXPECT_EQ(parse_integer("-7"), -7);
  EXPECT_EQ(parse_integer("0x6040"), 0x6040);
  EXPECT_EQ(parse_integer("0xFFFFFFFF"), 0xFFFFFFFFLL);
  EXPECT_FALSE(parse_integer("1.0"));
  EXPECT_FALSE(parse_integer("0x"));
  EXPECT_FALSE(parse_integer("99999999999999999999"));
  EXPECT_FALSE(parse_integer("+-1"));
}

TEST(TextUtil, DidYouMean) {
  const std::vector<std::string> keys{"cycle_time", "priority", "cpu"};
  EXPECT_EQ(closest_match("cycletime", keys), "cycle_time");
  EXPECT_EQ(closest_match("priorty", keys), "priority");
  EXPECT_EQ(closest_match("banana", keys), "");
  EXPECT_TRUE(is_valid_name("cell-1.a_b"));
  EXPECT_FALSE(is_valid_name("cell 1"));
  EXPECT_FALSE(is_valid_name("cell-1", false));
  EXPECT_FALSE(is_valid_name(std::string(64, 'a')));
}

// Dotted IPv4 as octets and as one host-order number; anything but four octets 0..255 refused.
TEST(TextUtil, Ipv4) {
  EXPECT_EQ(parse_ipv4("192.168.0.14"), (std::array<int, 4>{192, 168, 0, 14}));
  EXPECT_EQ(parse_ipv4_host("192.168.0.14"), 0xC0A8000EU);
  EXPECT_EQ(parse_ipv4_host("255.255.255.0"), 0xFFFFFF00U);
  EXPECT_EQ(parse_ipv4_host("0.0.0.0"), 0U);
  for (const char* bad : {"", "192.168.0", "192.168.0.256", "192.168.0.1.2", "192.168..1", "a.b.c.d", "24"})
    EXPECT_FALSE(parse_ipv4_host(bad).has_value()) << bad;
}

}  // namespace
}  // namespace drivegate::config
