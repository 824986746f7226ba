// NameOfStation rules [IEC 61158-6-10 §4.3, coding of the field NameOfStation].
#include "adapters/profinet/wire/station_name.hpp"

#include <gtest/gtest.h>

#include <string>

namespace drivegate::profinet {
namespace {

TEST(PnStationName, ValidNames) {
  for (const char* n : {"akd-1", "drive", "a", "line-3.cell-2.plant", "x1", "port-1", "port-0011", "port-001x",
                        "1.2.3", "1.2.3.4.5", "1.2.3.a", "xn", "device.port-001"}) {
    EXPECT_EQ(validate_name_of_station(n), NameError::None) << n;
  }
  EXPECT_EQ(validate_name_of_station(std::string(63, 'a')), NameError::None);
  // 240 octets: four labels of 59 and three dots.
  const std::string l(59, 'b');
  EXPECT_EQ(validate_name_of_station(l + "." + l + "." + l + "." + l + "x"), NameError::None);
}

TEST(PnStationName, EachRuleWithItsReason) {
  EXPECT_EQ(validate_name_of_station(""), NameError::Empty);
  EXPECT_EQ(validate_name_of_station(std::string(241, 'a')), NameError::TooLong);
  EXPECT_EQ(validate_name_of_station(std::string(64, 'a')), NameError::LabelTooLong);
  EXPECT_EQ(validate_name_of_station(".drive"), NameError::EmptyLabel);
  EXPECT_EQ(validate_name_of_station("drive."), NameError::EmptyLabel);
  EXPECT_EQ(validate_name_of_station("a..b"), NameError::EmptyLabel);
  EXPECT_EQ(validate_name_of_station("Drive-1"), NameError::UpperCase);
  EXPECT_EQ(validate_name_of_station("drive_1"), NameError::InvalidCharacter);
  EXPECT_EQ(validate_name_of_station("drive 1"), NameError::InvalidCharacter);
  EXPECT_EQ(validate_name_of_station("dr\xC3\xBC"), NameError::InvalidCharacter);
  EXPECT_EQ(validate_name_of_station("-drive"), NameError::HyphenAtLabelEdge);
  EXPECT_EQ(validate_name_of_station("drive-"), NameError::HyphenAtLabelEdge);
  EXPECT_EQ(validate_name_of_station("a.-b"), NameError::HyphenAtLabelEdge);
  EXPECT_EQ(validate_name_of_station("port-001"), NameError::LooksLikePortName);
  EXPECT_EQ(validate_name_of_station("port-001-00002"), NameError::LooksLikePortName);
  EXPECT_EQ(validate_name_of_station("port-001.plant"), NameError::LooksLikePortName);
  EXPECT_EQ(validate_name_of_station("xn-drive"), NameError::IdnaPrefix);
  EXPECT_EQ(validate_name_of_station("192.168.0.10"), NameError::LooksLikeIpAddress);
  EXPECT_EQ(validate_name_of_station("0.0.0.999"), NameError::LooksLikeIpAddress);
  EXPECT_EQ(to_string(NameError::UpperCase), "the name has upper-case letters; PROFINET names are lower case");
}

}  // namespace
}  // namespace drivegate::profinet
