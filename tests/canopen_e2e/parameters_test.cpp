// Parameters over the DDS parameter topic, answered by the simulated SD6 over SDO: a read by the
// drive's own parameter name, and SDO aborts surfacing as replies with their text.
#include "tests/canopen_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

class CanopenE2eParameters : public CanopenE2eUp {
 protected:
  client::ParamResult param(client::ParamRequest r) {
    r.axis = "sd6";
    return client_->param(r, 5s);
  }
};

TEST_F(CanopenE2eParameters, Sd6ParameterByNameAndSdoAborts) {
  // A83 is the SD6's bus address: 2000h + group A (0) x 200h + line 83 = 2053h:00
  // (stoeber-sd6-canopen.md §2.2), the node-ID 3.
  // Without an EDS the gateway does not know A83's type, and the SD6 answers without a size
  // (42h, stoeber-sd6-canopen.md §6.4): four bytes came, how many are A83 it cannot tell.
  client::ParamRequest a83;
  a83.name = "A83";
  auto r = param(a83);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("did not say how long the object is"), std::string::npos) << r.error;
  a83.type = "u8";
  r = param(a83);
  ASSERT_TRUE(r.ok) << r.error << diagnostics();
  EXPECT_EQ(r.data, std::vector<std::uint8_t>{3});
  EXPECT_EQ(r.index, 0x2053);
  EXPECT_EQ(r.subindex, 0);
  EXPECT_EQ(r.gateway, "e2e");

  // E200 resolves (TV-6: 28C8h:00) but this drive has no such object: the SDO abort comes back as
  // the reply, with its code and text.
  client::ParamRequest e200;
  e200.name = "E200";
  r = param(e200);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.index, 0x28C8);
  EXPECT_EQ(r.error_code, 0x06020000U) << r.error;
  EXPECT_NE(r.error.find("object does not exist in the object dictionary"), std::string::npos) << r.error;

  // Writing the read-only bus address is refused by the drive in the same way.
  client::ParamRequest write_a83 = a83;
  write_a83.write = true;
  write_a83.value = "5";
  r = param(write_a83);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error_code, 0x06010002U) << r.error;
  EXPECT_NE(r.error.find("attempt to write a read-only object"), std::string::npos) << r.error;

  // A name beyond the SD6's naming scheme never reaches the bus.
  client::ParamRequest too_far;
  too_far.name = "A600";
  r = param(too_far);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error_code, 0U) << r.error;
  EXPECT_FALSE(r.error.empty());

  // The drive itself is untouched and the axis stays up.
  r = param(a83);
  EXPECT_TRUE(r.ok && r.data == std::vector<std::uint8_t>{3}) << r.error;
  EXPECT_EQ(state("sd6").link, "operational");
}

// Objects of every size over the real SDO path (daemon and simulator in two processes): identity
// strings by segmented upload, a 4 KiB domain, 64-bit and REAL32 values both ways.
TEST_F(CanopenE2eParameters, StringsDomainsAnd64BitValuesOverSegmentedSdo) {
  const auto get = [&](const std::string& axis, std::uint16_t index, std::string type = {}) {
    client::ParamRequest q;
    q.axis = axis;
    q.index = index;
    q.type = std::move(type);
    return client_->param(q, 5s);
  };
  auto r = get("sd6", 0x1008);  // 19 characters: segmented, typed by CiA 301
  ASSERT_TRUE(r.ok) << r.error << diagnostics();
  EXPECT_EQ(r.type, core::ParamType::VisibleString);
  EXPECT_EQ(r.text(), "SD6 axis controller");
  r = get("akd", 0x1008);  // four characters "Yzzz": expedited (AKD part 1 §13.1)
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.text(), "M006");
  r = get("akd", 0x1009);  // the AKD has no hardware version string
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error_code, 0x06020000U) << r.error;
  r = get("sd6", 0x1008, "u32");  // the type says 4 bytes, the standard says a string
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("is a VISIBLE_STRING"), std::string::npos) << r.error;

  r = get("nord", 0x5FF0, "domain");
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_EQ(r.data.size(), 4096U);
  for (std::size_t i = 0; i < r.data.size(); ++i) ASSERT_EQ(r.data[i], static_cast<std::uint8_t>(i * 7 + 1)) << i;
  r = get("nord", 0x5FF1, "u64");
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(core::param_as_unsigned(r.type, r.data), 0x0123456789ABCDEFULL);
  r = get("nord", 0x5FF1, "u32");  // 8 bytes came: never cut to 4
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "5FF1h:00: the drive sent 8 bytes, a UNSIGNED32 has 4");

  client::ParamRequest set;
  set.axis = "nord";
  set.write = true;
  set.index = 0x5FF1;
  set.type = "i64";
  set.value = "-2";
  ASSERT_TRUE(client_->param(set, 5s).ok);
  EXPECT_EQ(get("nord", 0x5FF1, "i64").integer(), -2);
  set.index = 0x5FF2;
  set.type = "r32";
  set.value = "-0.125";
  ASSERT_TRUE(client_->param(set, 5s).ok);
  EXPECT_EQ(get("nord", 0x5FF2, "r32").text(), "-0.125");
  set.index = 0x5FF0;
  set.type = "domain";
  set.value = "de ad be ef 01 02 03 04 05";
  ASSERT_TRUE(client_->param(set, 5s).ok);
  EXPECT_EQ(get("nord", 0x5FF0, "domain").text(), "DE AD BE EF 01 02 03 04 05");
  set.index = 0x5FF1;  // a length the object does not take: the drive's abort comes back
  set.type = "u32";
  set.value = "1";
  r = client_->param(set, 5s);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error_code, 0x06070013U) << r.error;
}

}  // namespace
}  // namespace drivegate::test
