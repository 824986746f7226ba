#include "profiles/cia402/error_codes.hpp"

#include <gtest/gtest.h>

#include <array>

#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::cia402 {
namespace {

TEST(ErrorCodes, ExactCodes) {
  EXPECT_EQ(error_code_text(0x0000), "error reset / no error");
  EXPECT_EQ(error_code_text(0x1000), "generic error");
  EXPECT_EQ(error_code_text(0x2310), "continuous overcurrent (output)");
  EXPECT_EQ(error_code_text(0x3210), "DC link overvoltage");
  EXPECT_EQ(error_code_text(0x4310), "excess temperature drive (motor)");
  EXPECT_EQ(error_code_text(0x8611), "following error");
  EXPECT_EQ(error_code_text(0x8612), "reference limit");
  EXPECT_EQ(error_code_text(0xFF00), "device specific error");
}

TEST(ErrorCodes, FallsBackToTheClass) {
  EXPECT_EQ(error_code_text(0x2399), "current on the device output side (overcurrent / short circuit)");
  EXPECT_EQ(error_code_text(0x3999), "voltage");
  EXPECT_EQ(error_code_text(0x4299), "device temperature");
  EXPECT_EQ(error_code_text(0x5FFF), "device hardware");
  EXPECT_EQ(error_code_text(0x6123), "internal software");
  EXPECT_EQ(error_code_text(0x7398), "sensor");
  EXPECT_EQ(error_code_text(0x8100), "communication");
  EXPECT_EQ(error_code_text(0x86A0), "positioning controller monitoring");
  EXPECT_EQ(error_code_text(0xFF42), "device specific");
  EXPECT_EQ(error_code_text(0xA000), "unknown error code");
}

TEST(ErrorCodes, VendorTableWinsOverTheStandard) {
  const std::array vendor = {FaultText{0x7398, "F135 homing required"}, FaultText{0x2310, "F523 overcurrent"}};
  EXPECT_EQ(error_code_text(0x7398, vendor), "F135 homing required");
  EXPECT_EQ(error_code_text(0x2310, vendor), "F523 overcurrent");
  EXPECT_EQ(error_code_text(0x3210, vendor), "DC link overvoltage");
}

TEST(SdoAbort, KnownAndUnknownCodes) {
  EXPECT_EQ(sdo_abort_text(0x06090031), "value of parameter written too high (download only)");
  EXPECT_EQ(sdo_abort_text(0x06020000), "object does not exist in the object dictionary");
  EXPECT_EQ(sdo_abort_text(0x05040000), "SDO protocol timed out");
  EXPECT_EQ(sdo_abort_text(0x12345678), "unknown abort code");
}

}  // namespace
}  // namespace drivegate::cia402
