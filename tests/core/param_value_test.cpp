// Parameter values of every CiA 301 basic type: text to wire bytes and back, and the errors that
// keep a value from being cut to size.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/param_value.hpp"

namespace drivegate::core {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes enc(ParamType t, std::string_view text) {
  const auto e = encode_param(t, text);
  EXPECT_TRUE(e.error.empty()) << param_type_name(t) << " '" << text << "': " << e.error;
  return e.bytes;
}

std::string err(ParamType t, std::string_view text) {
  const auto e = encode_param(t, text);
  EXPECT_FALSE(e.error.empty()) << param_type_name(t) << " '" << text << "' encoded";
  return e.error;
}

TEST(ParamValue, NamesCiaIndicesAndSizes) {
  EXPECT_EQ(param_type_from_name("u32"), ParamType::U32);
  EXPECT_EQ(param_type_from_name("UNSIGNED32"), ParamType::U32);
  EXPECT_EQ(param_type_from_name("visible_string"), ParamType::VisibleString);
  EXPECT_EQ(param_type_from_name("float"), ParamType::R32);
  EXPECT_EQ(param_type_from_name("domain"), ParamType::Domain);
  EXPECT_EQ(param_type_from_name("u33"), std::nullopt);
  EXPECT_EQ(param_type_from_name(""), std::nullopt);
  // CiA 301 Table 44.
  EXPECT_EQ(param_type_from_cia(0x0007), ParamType::U32);
  EXPECT_EQ(param_type_from_cia(0x0010), ParamType::I24);
  EXPECT_EQ(param_type_from_cia(0x0011), ParamType::R64);
  EXPECT_EQ(param_type_from_cia(0x001B), ParamType::U64);
  EXPECT_EQ(param_type_from_cia(0x000F), ParamType::Domain);
  EXPECT_EQ(param_type_from_cia(0x0040), ParamType::Unknown);  // vendor-defined
  EXPECT_EQ(param_type_size(ParamType::I48), 6U);
  EXPECT_EQ(param_type_size(ParamType::VisibleString), 0U);
}

TEST(ParamValue, IntegersRoundTripAtTheirLimits) {
  EXPECT_EQ(enc(ParamType::I16, "-266"), (Bytes{0xF6, 0xFE}));  // AKD part 1 §14 vector 2
  EXPECT_EQ(enc(ParamType::U32, "0x00020192"), (Bytes{0x92, 0x01, 0x02, 0x00}));
  EXPECT_EQ(enc(ParamType::I16, "0xFFFF"), (Bytes{0xFF, 0xFF}));  // a bit pattern in hex
  EXPECT_EQ(enc(ParamType::I24, "-8388608"), (Bytes{0x00, 0x00, 0x80}));
  EXPECT_EQ(enc(ParamType::U64, "18446744073709551615"), Bytes(8, 0xFF));
  EXPECT_EQ(enc(ParamType::I64, "-9223372036854775808"), (Bytes{0, 0, 0, 0, 0, 0, 0, 0x80}));
  EXPECT_EQ(enc(ParamType::Bool, "true"), Bytes{1});
  EXPECT_EQ(format_param(ParamType::I24, Bytes{0x00, 0x00, 0x80}), "-8388608");
  EXPECT_EQ(format_param(ParamType::U40, Bytes{1, 2, 3, 4, 5}), "21542142465");
  EXPECT_EQ(format_param(ParamType::I64, Bytes{0, 0, 0, 0, 0, 0, 0, 0x80}), "-9223372036854775808");
  EXPECT_EQ(format_param_hex(ParamType::U16, Bytes{0x40, 0x02}), "0x0240");
  EXPECT_EQ(param_as_signed(ParamType::I8, Bytes{0xFD}), -3);
  EXPECT_EQ(param_as_unsigned(ParamType::U64, Bytes(8, 0xFF)), 0xFFFFFFFFFFFFFFFFULL);

  EXPECT_EQ(err(ParamType::U16, "70000"), "value '70000' is outside the range of UNSIGNED16 (0 to 65535)");
  EXPECT_EQ(err(ParamType::I8, "128"), "value '128' is outside the range of INTEGER8 (-128 to 127)");
  EXPECT_EQ(err(ParamType::U8, "-1"), "value '-1' is outside the range of UNSIGNED8 (0 to 255)");
  EXPECT_EQ(err(ParamType::I16, "0x10000"), "value '0x10000' is outside the range of INTEGER16 (-32768 to 32767)");
  EXPECT_NE(err(ParamType::U64, "18446744073709551616").find("outside the range"), std::string::npos);
  EXPECT_NE(err(ParamType::U32, "12abc").find("is not a number"), std::string::npos);
  EXPECT_NE(err(ParamType::U32, "").find("is not a number"), std::string::npos);
  EXPECT_NE(err(ParamType::Bool, "2").find("outside the range"), std::string::npos);
}

TEST(ParamValue, RealsAreExactAndFinite) {
  EXPECT_EQ(enc(ParamType::R32, "4.5"), (Bytes{0x00, 0x00, 0x90, 0x40}));
  EXPECT_EQ(format_param(ParamType::R32, enc(ParamType::R32, "0.1")), "0.1");  // shortest round trip
  EXPECT_EQ(format_param(ParamType::R64, enc(ParamType::R64, "-1e300")), "-1e+300");
  EXPECT_NE(err(ParamType::R32, "nan").find("not a finite number"), std::string::npos);
  EXPECT_NE(err(ParamType::R64, "inf").find("not a finite number"), std::string::npos);
  EXPECT_NE(err(ParamType::R32, "1e39").find("outside the range of REAL32"), std::string::npos);
  EXPECT_NE(err(ParamType::R32, "4,5").find("is not a number"), std::string::npos);
}

TEST(ParamValue, StringsAndBytes) {
  EXPECT_EQ(enc(ParamType::VisibleString, "AKD"), (Bytes{'A', 'K', 'D'}));
  EXPECT_NE(err(ParamType::VisibleString, "caf\xC3\xA9").find("character 4 is byte 0xC3"), std::string::npos);
  EXPECT_EQ(enc(ParamType::UnicodeString, "\xC3\xA9\xF0\x9F\x98\x80"), (Bytes{0xE9, 0x00, 0x3D, 0xD8, 0x00, 0xDE}));
  EXPECT_EQ(format_param(ParamType::UnicodeString, Bytes{0xE9, 0x00, 0x3D, 0xD8, 0x00, 0xDE}), "\xC3\xA9\xF0\x9F\x98\x80");
  EXPECT_NE(err(ParamType::UnicodeString, "\xC3").find("not UTF-8"), std::string::npos);
  EXPECT_EQ(enc(ParamType::OctetString, "01 02:0a-FF"), (Bytes{1, 2, 0x0A, 0xFF}));
  EXPECT_EQ(enc(ParamType::Domain, "0x01020a"), (Bytes{1, 2, 0x0A}));
  EXPECT_NE(err(ParamType::Domain, "012").find("not whole bytes"), std::string::npos);
  EXPECT_NE(err(ParamType::Domain, "zz").find("not hex bytes"), std::string::npos);
  EXPECT_NE(err(ParamType::Domain, "").find("empty value"), std::string::npos);
  EXPECT_EQ(err(ParamType::TimeOfDay, "01 02"), "TIME_OF_DAY takes 6 bytes, got 2");
  // Fixed-length strings padded with NULs show without the padding; other bytes are escaped.
  EXPECT_EQ(format_param(ParamType::VisibleString, Bytes{'T', 'r', 'i', 'o', 0, 0}), "Trio");
  EXPECT_EQ(format_param(ParamType::VisibleString, Bytes{'a', 0x01, '\\'}), "a\\x01\\\\");
  EXPECT_EQ(format_param(ParamType::Unknown, Bytes{0xDE, 0xAD}), "DE AD");
  // 4 KiB is the most a parameter carries.
  std::string big;
  for (int i = 0; i < 4097; ++i) big += "00";
  EXPECT_NE(err(ParamType::Domain, big).find("at most 4096"), std::string::npos);
  EXPECT_NE(err(ParamType::Unknown, "1").find("type is not known"), std::string::npos);
}

TEST(ParamValue, SizesThatDoNotFitAreNamed) {
  EXPECT_EQ(param_size_error(ParamType::U32, 31), "31 bytes do not fit a UNSIGNED32, which has 4");
  EXPECT_EQ(param_size_error(ParamType::U32, 4), "");
  EXPECT_EQ(param_size_error(ParamType::VisibleString, 31), "");
  EXPECT_EQ(format_param(ParamType::U32, Bytes{1, 2}), "01 02");  // never a number from the wrong size
  EXPECT_EQ(param_as_signed(ParamType::U32, Bytes{1, 2}), std::nullopt);
}

TEST(ParamValue, HexFirstObjects) {
  EXPECT_TRUE(param_reads_as_hex(0x1000, 0));
  EXPECT_TRUE(param_reads_as_hex(0x1018, 1));
  EXPECT_FALSE(param_reads_as_hex(0x1018, 0));  // a count
  EXPECT_TRUE(param_reads_as_hex(0x1400, 1));   // COB-ID
  EXPECT_FALSE(param_reads_as_hex(0x1400, 2));  // transmission type
  EXPECT_TRUE(param_reads_as_hex(0x1A00, 3));   // mapping entry
  EXPECT_TRUE(param_reads_as_hex(0x6041, 0));
  EXPECT_FALSE(param_reads_as_hex(0x6081, 0));
}

}  // namespace
}  // namespace drivegate::core
