// The whole exchange the engines produce (Connect, parameter write, PrmEnd, ApplicationReady,
// record reads and writes, Release) in Ethernet/IPv4/UDP frames dissects cleanly in tshark: every
// frame DCE/RPC + PROFINET IO, nothing malformed, no expert error or warning, every response OK.
// Skipped without tshark.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "tests/profinet_cm/cm_harness.hpp"
#include "tests/profinet_rpc/udp_frame.hpp"
#include "tests/support/pcap.hpp"

namespace drivegate::profinet {
namespace {

using namespace test;

test::UdpEndpoint frame_endpoint(const profinet::UdpEndpoint& e) {
  test::UdpEndpoint f;
  f.mac = e.ip == kPlcIp ? kControllerMac : kDeviceMac;
  f.ip = {static_cast<std::uint8_t>(e.ip >> 24), static_cast<std::uint8_t>(e.ip >> 16),
          static_cast<std::uint8_t>(e.ip >> 8), static_cast<std::uint8_t>(e.ip)};
  f.port = e.port;
  return f;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t c = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++c;
  return c;
}

TEST(PnCmTshark, EngineExchangeDissectsCleanly) {
  Bench b;
  b.start();
  ASSERT_EQ(b.plc->state(), CmClientState::DataExchange) << b.plc->reason();
  b.plc->submit_read(0, 0, 1, record_index::kIm0);
  b.plc->submit_write(kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, kPnu930);
  b.run_for(20ms);
  b.plc->release(b.now, b.plc_out);
  b.shuttle();
  ASSERT_EQ(b.plc->state(), CmClientState::Released);
  ASSERT_EQ(b.log.size(), 14U);
  std::vector<std::vector<std::uint8_t>> frames;
  std::uint16_t ip_id = 1;
  for (const Packet& p : b.log) frames.push_back(udp_frame(frame_endpoint(p.from), frame_endpoint(p.to), p.bytes, ip_id++));
  const std::optional<std::string> dissected = drivegate::test::tshark_dissect(frames);
  if (!dissected) GTEST_SKIP() << "tshark not installed (scripts/install-deps.sh)";
  const std::string& out = *dissected;
  EXPECT_EQ(out.find("Malformed"), std::string::npos) << out;
  EXPECT_EQ(out.find("Exception"), std::string::npos) << out;
  EXPECT_EQ(out.find("[Severity level: Error]"), std::string::npos) << out;
  EXPECT_EQ(out.find("[Severity level: Warning]"), std::string::npos) << out;
  EXPECT_EQ(count(out, "DCE/RPC"), 14U) << out;
  EXPECT_EQ(count(out, "PROFINET IO"), 14U) << out;
  for (const char* field : {"Operation: Connect (0)", "Operation: Write (3)", "Operation: Read (2)",
                            "Operation: Control (4)", "Operation: Release (1)", "Command: ParameterEnd",
                            "Command: ApplicationReady", "OrderID: AKD-P00306-NBPN-0000", "[Request in frame: 13]"}) {
    EXPECT_NE(out.find(field), std::string::npos) << "missing: " << field;
  }
  EXPECT_EQ(out.find("ModuleDiffBlock"), std::string::npos) << "no module diff for a matching device";
  // Seven responses, each with PNIOStatus OK in the NDR part.
  EXPECT_GE(count(out, "Status: OK"), 7U) << out;
}

}  // namespace
}  // namespace drivegate::profinet
