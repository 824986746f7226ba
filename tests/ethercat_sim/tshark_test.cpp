// Frames the simulator answers dissect cleanly in Debian's tshark (issue 9: "every frame it sends
// and receives must dissect cleanly, no Malformed, CoE fields filled"): a bring-up with SDO
// traffic and an emergency is captured (frames sent and returned), written as a classic pcap file
// (link type 1 = Ethernet) and read with `tshark -V` (tests/support/pcap.hpp). Skipped when tshark
// is not installed; KEEP_PCAP=1 keeps the file.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "tests/ethercat_sim/coe_line.hpp"
#include "tests/support/pcap.hpp"

namespace drivegate::ethercat::sim {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(EthercatSimTshark, BringUpDissectsCleanly) {
  std::vector<Bytes> capture;
  test::CoeLine l;
  l.bus.capture = &capture;
  l.bus.brd(reg::kType, 1);
  l.preop();
  std::size_t n = encode_sdo_upload_request(l.req, l.next(), 0x1000, 0);
  l.sdo(std::span(l.req.data(), n));
  n = encode_sdo_upload_request(l.req, l.next(), 0x2001, 0);  // normal upload + segments
  l.sdo(std::span(l.req.data(), n));
  n = encode_sdo_upload_segment_request(l.req, l.next(), false);
  l.sdo(std::span(l.req.data(), n));
  n = encode_sdo_upload_request(l.req, l.next(), 0x3000, 0);  // abort
  l.sdo(std::span(l.req.data(), n));
  n = encode_get_od_list_request(l.req, l.next(), OdListType::All);
  l.put(std::span(l.req.data(), n));
  l.get();
  l.esc.post_emergency(CoeEmergency{0x8100, 0x11, {1, 2, 3, 4, 5}});
  l.get();
  ASSERT_GT(capture.size(), 20U);

  const std::optional<std::string> dissected = drivegate::test::tshark_dissect(capture, 100);
  if (!dissected) GTEST_SKIP() << "tshark not installed";
  const std::string& out = *dissected;
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.find("Malformed"), std::string::npos) << out;
  EXPECT_EQ(out.find("Exception"), std::string::npos) << out;
  for (const char* field : {"Type: SDO Res (3)", "Initiate Upload Response: 0x43", "Initiate Upload Response: 0x41",
                            "Abort code: 0x06020000", "Info OpCode: List Res (2)", "Type: EMERGENCY (1)",
                            "Idx=0x2001", "Cmd: 'BRD'", "Working Cnt: 1"}) {
    EXPECT_NE(out.find(field), std::string::npos) << "missing: " << field;
  }
  EXPECT_NE(out.find("Frame " + std::to_string(capture.size()) + ":"), std::string::npos);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
