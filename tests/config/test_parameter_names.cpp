// Manufacturer parameter names -> objects (STÖBER: stoeber-sd6-canopen.md §2.2).
#include <gtest/gtest.h>

#include "config/canopen/parameter_names.hpp"

namespace drivegate::config {
namespace {

constexpr ParameterNaming kSd6{0x2000, 0x200, 511};

cia402::ObjectId id(std::uint16_t index, std::uint8_t sub) { return {index, sub}; }

TEST(ParameterNames, ManualVectors) {
  // TV-6: E200[0] -> 8192 + 4 * 512 + 200 = 10440 = 28C8h, sub 0.
  EXPECT_EQ(parse_parameter_name("E200[0]", kSd6), id(0x28C8, 0));
  // The digest's table of named parameters [§2.2].
  EXPECT_EQ(parse_parameter_name("A83", kSd6), id(0x2053, 0));
  EXPECT_EQ(parse_parameter_name("A00[2]", kSd6), id(0x2000, 2));
  EXPECT_EQ(parse_parameter_name("A213", kSd6), id(0x20D5, 0));
  EXPECT_EQ(parse_parameter_name("I06", kSd6), id(0x3006, 0));
  EXPECT_EQ(parse_parameter_name("Z0", kSd6), id(0x5200, 0));
  EXPECT_EQ(parse_parameter_name("Z511[255]", kSd6), id(0x53FF, 255));
  EXPECT_EQ(parse_parameter_name("e82", kSd6), id(0x2852, 0));  // letters in either case
}

TEST(ParameterNames, RefusedWithTheReason) {
  // A540 is a real SD6 parameter, but lines >= 512 fall into the next group's window [§2.2].
  const auto line = resolve_parameter_name("A540", kSd6);
  EXPECT_FALSE(line.id);
  EXPECT_EQ(line.error.rfind("line 540 is beyond 511", 0), 0U) << line.error;
  const auto element = resolve_parameter_name("A10[300]", kSd6);
  EXPECT_FALSE(element.id);
  EXPECT_EQ(element.error, "element 300 is beyond 255, the highest CANopen sub-index");
  for (const char* bad : {"", "83", "A", "A-1", "A8x", "A83[", "A83[]", "A83[1", "A[1]", "A83]", "AA83", "A 83",
                          "A83[+1]", "A1234567"}) {
    const auto r = resolve_parameter_name(bad, kSd6);
    EXPECT_FALSE(r.id) << bad;
    EXPECT_NE(r.error.find("must be a parameter name such as A83"), std::string::npos) << bad << ": " << r.error;
  }
}

TEST(ParameterNames, IndexBeyondSixteenBitsIsRefused) {
  const ParameterNaming wide{0xF000, 0x200, 511};
  EXPECT_EQ(parse_parameter_name("H511", wide), id(0xFFFF, 0));  // F000h + 7 * 200h + 511
  const auto r = resolve_parameter_name("I0", wide);               // F000h + 8 * 200h = 1_0000h
  EXPECT_FALSE(r.id);
  EXPECT_EQ(r.error, "group I line 0 gives an index beyond FFFFh");
}

}  // namespace
}  // namespace drivegate::config
