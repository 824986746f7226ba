// The frames a DcpClient and DcpResponders exchange dissect cleanly in tshark (tests/support/pcap.hpp):
// Identify all and by name with their responses, Set name / IP / Signal with their responses, and
// a Set refused with a BlockError. No "Malformed", no expert warning or error, fields named.
// Skipped when tshark is not installed.
#include <gtest/gtest.h>

#include "tests/profinet_dcp/hub.hpp"
#include "tests/support/pcap.hpp"

namespace drivegate::profinet::test {
namespace {

TEST(PnDcpTshark, ExchangedFramesDissectCleanly) {
  Hub hub;
  DcpClient client(kControllerMac);
  DcpResponder a(device(0x0301, "drive-a", suite(10)));
  DcpResponder b(device(0x0302, "drive-b"));
  hub.add(client);
  hub.add(a);
  hub.add(b);
  std::array<DcpStation, 4> found{};
  (void)client.identify_all(found, 4);
  (void)client.identify_name("drive-b", std::span(found).subspan(2));
  (void)client.set_ip(b.mac(), suite(11), DcpQualifier::Permanent);
  (void)client.set_name(a.mac(), "drive-c", DcpQualifier::Temporary);
  (void)client.signal(a.mac());
  ASSERT_TRUE(hub.run_until([&] { return client.idle(); }));
  a.set_in_operation(true);
  (void)client.set_ip(a.mac(), suite(12), DcpQualifier::Permanent);
  ASSERT_TRUE(hub.run_until([&] { return client.idle(); }));
  // Identify all + 2 answers, Identify by name + 1 answer, 4 Sets + 4 answers.
  ASSERT_EQ(hub.log.size(), 13U);

  const std::optional<std::string> out = drivegate::test::tshark_dissect(hub.log);
  if (!out) GTEST_SKIP() << "tshark is not installed";
  EXPECT_EQ(out->find("Malformed"), std::string::npos) << *out;
  EXPECT_EQ(out->find("Expert Info (Error"), std::string::npos) << *out;
  EXPECT_EQ(out->find("Expert Info (Warning"), std::string::npos) << *out;
  for (const char* field : {"Identify", "NameOfStation: drive-a", "NameOfStation: drive-b", "Set", "Signal",
                            "IP: 192.168.0.11", "Response Success", "drive-c",
                            "BlockError: In operation, SET not possible (6)"}) {
    EXPECT_NE(out->find(field), std::string::npos) << "missing: " << field << "\n" << *out;
  }
}

}  // namespace
}  // namespace drivegate::profinet::test
