// Record addresses (rec:SLOT:SUBSLOT:INDEX[@API]) and the device identity a link detail carries,
// as drivegatectl and the daemon read them.
#include <gtest/gtest.h>

#include "core/device_identity.hpp"
#include "core/record_address.hpp"

namespace drivegate::core {
namespace {

RecordAddress parsed(std::string_view text) {
  const ParsedRecordAddress p = parse_record_address(text);
  EXPECT_TRUE(p.address) << p.error;
  return p.address.value_or(RecordAddress{});
}

std::string error_of(std::string_view text) {
  const ParsedRecordAddress p = parse_record_address(text);
  EXPECT_FALSE(p.address) << text;
  return p.error;
}

TEST(RecordAddress, DecimalHexAndTheOptionalApi) {
  RecordAddress a = parsed("rec:0:1:0xAFF0");
  EXPECT_TRUE(a.valid);
  EXPECT_FALSE(a.api_given);
  EXPECT_EQ(a.slot, 0);
  EXPECT_EQ(a.subslot, 1);
  EXPECT_EQ(a.index, 0xAFF0);
  EXPECT_EQ(a.io, kNoIo);
  a = parsed("REC:0x1:32769:47@0x3A00");
  EXPECT_TRUE(a.api_given);
  EXPECT_EQ(a.api, 0x3A00U);
  EXPECT_EQ(a.subslot, 0x8001);
  EXPECT_EQ(a.index, 47);
  EXPECT_EQ(parsed("rec:65535:65535:65535@4294967295").api, 0xFFFFFFFFU);
  EXPECT_EQ(format_record_address(parsed("rec:1:1:47@14848")), "rec:1:1:0x002F@0x3A00");
  EXPECT_EQ(format_record_address(parsed("rec:0:1:0xaff0")), "rec:0:1:0xAFF0");
}

TEST(RecordAddress, ApartFromObjectsNamesAndPnus) {
  EXPECT_TRUE(is_record_address("rec:0"));
  EXPECT_FALSE(is_record_address("p930"));
  EXPECT_FALSE(is_record_address("6041h:00"));
  EXPECT_FALSE(is_record_address("record"));
  EXPECT_FALSE(is_record_address("rec"));
}

TEST(RecordAddress, BadSyntaxIsNamed) {
  EXPECT_NE(error_of("rec:0:1").find("a slot, a subslot and an index are needed; write rec:SLOT:SUBSLOT:INDEX[@API]"),
            std::string::npos);
  EXPECT_NE(error_of("rec:0:1:2:3").find("more than three numbers"), std::string::npos);
  EXPECT_NE(error_of("rec:0:1:0x10000").find("the index '0x10000' is no number of 0..0xFFFF"), std::string::npos);
  EXPECT_NE(error_of("rec:x:1:2").find("the slot 'x'"), std::string::npos);
  EXPECT_NE(error_of("rec:0::2").find("the subslot ''"), std::string::npos);
  EXPECT_NE(error_of("rec:0:1:-2").find("the index '-2'"), std::string::npos);
  EXPECT_NE(error_of("rec:0:1:0x").find("the index '0x'"), std::string::npos);
  EXPECT_NE(error_of("rec:0:1:2@").find("the API '' is no 32-bit number"), std::string::npos);
  EXPECT_NE(error_of("rec:0:1:2@0x100000000").find("the API"), std::string::npos);
  EXPECT_NE(error_of("rec:0:1:2 ").find("the index '2 '"), std::string::npos);
}

TEST(DeviceIdentity, ReadFromTheLinkDetail) {
  const auto id = identity_in_link_detail(
      "station \"akd-x\" (02:1b:1b:00:0a:01 at 192.168.0.10): in data exchange (AR 2); I&M0 order 6ES7 155-6AU01 "
      "serial S C-X4U12345 hw 12 sw V4.2.1");
  ASSERT_TRUE(id);
  EXPECT_EQ(id->order_id, "6ES7 155-6AU01");
  EXPECT_EQ(id->serial_number, "S C-X4U12345");
  EXPECT_EQ(id->hardware_revision, "12");
  EXPECT_EQ(id->software_revision, "V4.2.1");
  EXPECT_FALSE(identity_in_link_detail("node 35: identity: 1018h:01 reads 0x0000006A"));
  EXPECT_FALSE(identity_in_link_detail("station \"akd-x\" (...): in data exchange (AR 1); I&M0 not read: truncated"));
  EXPECT_FALSE(identity_in_link_detail("...; I&M0 order X serial Y hw 1"));
  EXPECT_FALSE(identity_in_link_detail("...; I&M0 order X serial Y hw 1 sw "));
}

}  // namespace
}  // namespace drivegate::core
