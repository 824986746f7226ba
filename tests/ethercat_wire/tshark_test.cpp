// Frames written by the codecs dissect cleanly in Debian's tshark (issue 9: "must dissect cleanly
// in tshark, no Malformed, CoE fields filled"). The frames go through a classic pcap file (link
// type 1 = Ethernet) to `tshark -r FILE -V` (tests/support/pcap.hpp). Skipped when tshark is not
// installed (scripts/install-deps.sh installs it).
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "adapters/ethercat/wire/frame.hpp"
#include "adapters/ethercat/wire/mailbox.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "tests/support/pcap.hpp"

namespace drivegate::ethercat {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr MacAddress kSrc{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
constexpr std::uint16_t kSlave = 0x1001;
constexpr std::uint16_t kMailboxSize = 128;

// One datagram carrying a mailbox: FPWR into SM0 (1000h) or FPRD of SM1 (1080h), padded to the
// mailbox size as a master writes and reads it.
Bytes mailbox_frame(Command cmd, std::uint16_t ado, std::uint8_t index, std::span<const std::uint8_t> mbx) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(buf, kBroadcastMac, kSrc);
  EXPECT_TRUE(b.add(cmd, index, physical_address(kSlave, ado), kMailboxSize, mbx, 0, 1).ok());
  const auto f = b.finish();
  return Bytes(f.begin(), f.end());
}

std::vector<Bytes> frames() {
  std::vector<Bytes> out;
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  {  // start-up: count slaves, address the first, read AL status, read the SII
    FrameBuilder b(buf, kBroadcastMac, kSrc);
    const std::array<std::uint8_t, 2> addr{0x01, 0x10};
    const std::array<std::uint8_t, 6> sii_read{0x80, 0x01, 0x08, 0x00, 0x00, 0x00};  // read word 8
    EXPECT_TRUE(b.add(Command::BRD, 0, physical_address(0, reg::kType), 1, {}, 0, 2).ok());
    EXPECT_TRUE(b.add(Command::APWR, 1, physical_address(auto_increment_adp(0), reg::kStationAddress), 2, addr, 0, 1).ok());
    EXPECT_TRUE(b.add(Command::APRD, 2, physical_address(auto_increment_adp(1), reg::kAlStatus), 2, {}, 0, 1).ok());
    EXPECT_TRUE(b.add(Command::FPWR, 3, physical_address(kSlave, reg::kSiiControl), 6, sii_read, 0, 1).ok());
    const auto f = b.finish();
    out.emplace_back(f.begin(), f.end());
  }
  {  // every other command once
    FrameBuilder b(buf, kBroadcastMac, kSrc);
    const std::array<Command, 11> cmds{Command::NOP,  Command::APRW, Command::FPRD, Command::FPRW,
                                       Command::BWR,  Command::BRW,  Command::LRD,  Command::LWR,
                                       Command::LRW,  Command::ARMW, Command::FRMW};
    std::uint8_t idx = 10;
    for (const Command c : cmds) {
      const std::uint32_t adr = addressing_of(c) == Addressing::Logical ? 0x00010000U
                                                                        : physical_address(kSlave, reg::kDcSystemTime);
      EXPECT_TRUE(b.add(c, idx++, adr, 8, {}, 0, expected_wkc(c, 1)).ok());
    }
    const auto f = b.finish();
    out.emplace_back(f.begin(), f.end());
  }
  {  // the cyclic frame: FRMW of the reference clock, then LRW of the image (TV-7 IP-mode outputs)
    FrameBuilder b(buf, kBroadcastMac, kSrc);
    const std::array<std::uint8_t, 12> image{0x1F, 0x00, 0x45, 0x23, 0x01, 0x00, 0x27, 0x00, 0xA0, 0x86, 0x01, 0x00};
    EXPECT_TRUE(b.add(Command::FRMW, 0x40, physical_address(kSlave, reg::kDcSystemTime), 8, {}, 0, 2).ok());
    EXPECT_TRUE(b.add(Command::LRW, 0x41, 0x00010000, 12, image, 0, 3).ok());
    const auto f = b.finish();
    out.emplace_back(f.begin(), f.end());
  }
  std::array<std::uint8_t, kMailboxSize> mbx{};
  // TV-6 step 3 into SM0, the response and an EMCY (TV-4) from SM1.
  if (encode_sdo_download_value(mbx, 1, 0x1600, 1, 0x60400010, 4) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPWR, 0x1000, 0x50, mbx));
  mbx.fill(0);
  if (encode_sdo_download_response(mbx, 1, 0x1600, 1) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPRD, 0x1080, 0x51, mbx));
  mbx.fill(0);
  CoeEmergency e;
  e.error_code = 0x8100;
  e.error_register = 0x11;
  if (encode_emergency(mbx, 2, e) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPRD, 0x1080, 0x52, mbx));
  // Upload of 1008h: request, normal response, segment request and last segment.
  const Bytes name{'d', 'r', 'i', 'v', 'e', 'g', 'a', 't', 'e', '-', 'f', '1'};
  mbx.fill(0);
  if (encode_sdo_upload_request(mbx, 3, 0x1008, 0) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPWR, 0x1000, 0x53, mbx));
  mbx.fill(0);
  if (encode_sdo_upload_normal_response(mbx, 3, 0x1008, 0, 12, std::span(name).first(9)) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPRD, 0x1080, 0x54, mbx));
  mbx.fill(0);
  if (encode_sdo_upload_segment_request(mbx, 4, false) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPWR, 0x1000, 0x55, mbx));
  mbx.fill(0);
  if (encode_sdo_upload_segment_response(mbx, 4, false, true, std::span(name).subspan(9)) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPRD, 0x1080, 0x56, mbx));
  // Abort and SDO information.
  mbx.fill(0);
  if (encode_sdo_abort(mbx, 5, 0x2000, 0, 0x06020000) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPRD, 0x1080, 0x57, mbx));
  mbx.fill(0);
  if (encode_get_od_list_request(mbx, 6, OdListType::All) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPWR, 0x1000, 0x58, mbx));
  mbx.fill(0);
  const std::array<std::uint16_t, 4> idx{0x1000, 0x1018, 0x6040, 0x6041};
  if (encode_get_od_list_response(mbx, 6, OdListType::All, true, 0, idx) == 0) ADD_FAILURE();
  out.push_back(mailbox_frame(Command::FPRD, 0x1080, 0x59, mbx));
  return out;
}

TEST(EcatTshark, FramesDissectCleanly) {
  const std::vector<Bytes> fs = frames();
  const std::optional<std::string> dissected = drivegate::test::tshark_dissect(fs);
  if (!dissected) GTEST_SKIP() << "tshark not installed (scripts/install-deps.sh)";
  const std::string& out = *dissected;
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.find("Malformed"), std::string::npos) << out;
  EXPECT_EQ(out.find("Exception"), std::string::npos) << out;
  for (const char* field : {"EtherCAT frame header", "Cmd: 'BRD'", "Cmd: 'APWR'", "Cmd: 'APRD'", "Cmd: 'FPWR'",
                            "Cmd: 'NOP'", "Cmd: 'APRW'", "Cmd: 'FPRD'", "Cmd: 'FPRW'", "Cmd: 'BWR'", "Cmd: 'BRW'",
                            "Cmd: 'LRD'", "Cmd: 'LWR'", "Cmd: 'LRW'", "Cmd: 'ARMW'", "Cmd: 'FRMW'",
                            "Working Cnt: 3", "More EtherCAT datagrams will follow", "Last EtherCAT datagram",
                            "CoE (CANopen over EtherCAT)", "SDO Req : 'Initiate Download' (1) Idx=0x1600 Sub=1",
                            "EMERGENCY", "Index: 0x1008"}) {
    EXPECT_NE(out.find(field), std::string::npos) << "missing: " << field;
  }
  // Every frame was read: the last one is frame N.
  EXPECT_NE(out.find("Frame " + std::to_string(fs.size()) + ":"), std::string::npos);
}

}  // namespace
}  // namespace drivegate::ethercat
