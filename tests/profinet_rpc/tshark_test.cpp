// The connection management datagrams dissect cleanly in Debian's tshark: a controller/device
// exchange from Connect to Release (Connect, Write of record 47, Read of I&M0, PrmEnd,
// ApplicationReady, Release, each with its response) in Ethernet/IPv4/UDP frames to and from
// port 34964, through a classic pcap file (tests/support/pcap.hpp). Every frame must be DCERPC +
// PNIO, nothing malformed, no expert errors, every PNIO status OK. Skipped without tshark.
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "adapters/profinet/wire/rpc_calls.hpp"
#include "adapters/profinet/wire/rpc_connect.hpp"
#include "tests/profinet_rpc/scenario.hpp"
#include "tests/profinet_rpc/udp_frame.hpp"
#include "tests/support/pcap.hpp"
#include "tests/support/run_program.hpp"

namespace drivegate::profinet {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::Scenario;

constexpr test::UdpEndpoint kPlc{test::kControllerMac, {192, 168, 0, 1}, 0xC001};
constexpr test::UdpEndpoint kDrive{test::kDeviceMac, {192, 168, 0, 2}, kRpcUdpPort};
constexpr test::UdpEndpoint kDriveClient{test::kDeviceMac, {192, 168, 0, 2}, 0xC002};
constexpr test::UdpEndpoint kPlcServer{test::kControllerMac, {192, 168, 0, 1}, kRpcUdpPort};

struct Capture {
  std::vector<Bytes> frames;
  std::uint16_t ip_id = 1;
  void add(const test::UdpEndpoint& from, const test::UdpEndpoint& to, std::span<const std::uint8_t> d) {
    ASSERT_FALSE(d.empty());
    frames.push_back(test::udp_frame(from, to, d, ip_id++));
  }
};

std::vector<Bytes> exchange(ByteOrder order) {
  Capture cap;
  std::array<std::uint8_t, 1464> buf{};
  const Scenario s;
  const PnioStatus ok{};
  std::uint32_t seq = 0;

  // Connect
  RpcHeader req = test::device_call(Opnum::Connect, seq++, order);
  std::size_t n = encode_connect_request(req, test::kArgsMaximum, s.connect(), buf);
  cap.add(kPlc, kDrive, std::span(buf).first(n));
  const std::array<IocrBlockRes, 2> iocrs{{{iocr_type::kInput, 1, 0xC001}, {iocr_type::kOutput, 2, 0xC002}}};
  ConnectResponse cres;
  cres.ar = {ar_type::kIocarSingle, test::kArUuid, 1, test::kDeviceMac, kEtherTypePnio};
  cres.iocrs = iocrs;
  n = encode_connect_response(response_header_for(req, 1), ok, test::kArgsMaximum, cres, buf);
  cap.add(kDrive, kPlc, std::span(buf).first(n));

  // Write PNU 930 = 2 through record 47 on slot 1 (digest §5.5 request bytes).
  const std::array<std::uint8_t, 14> pnu930{0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03,
                                            0xA2, 0x00, 0x00, 0x42, 0x01, 0x00, 0x02};
  req = test::device_call(Opnum::Write, seq++, order);
  RecordReqHeader wr;
  wr.type = block_type::kWriteReqHeader;
  wr.sequence_number = 1;
  wr.ar_uuid = test::kArUuid;
  wr.api = test::kProfidriveApi;
  wr.slot = 1;
  wr.subslot = 1;
  wr.index = record_index::kAkdParameterAccess;
  n = encode_write_request(req, test::kArgsMaximum, wr, pnu930, buf);
  cap.add(kPlc, kDrive, std::span(buf).first(n));
  wr.record_data_length = pnu930.size();
  n = encode_write_response(response_header_for(req, 1), ok, test::kArgsMaximum,
                            record_response_for(wr, static_cast<std::uint32_t>(pnu930.size())), buf);
  cap.add(kDrive, kPlc, std::span(buf).first(n));

  // Read I&M0 of the DAP.
  req = test::device_call(Opnum::Read, seq++, order);
  RecordReqHeader rd;
  rd.type = block_type::kReadReqHeader;
  rd.sequence_number = 2;
  rd.ar_uuid = test::kArUuid;
  rd.slot = 0;
  rd.subslot = 1;
  rd.index = record_index::kIm0;
  rd.record_data_length = 4096;
  n = encode_read_request(req, test::kArgsMaximum, rd, buf);
  cap.add(kPlc, kDrive, std::span(buf).first(n));
  Im0 im;
  im.vendor_id = test::kDevice.vendor_id;
  im.order_id = "AKD-P00306-NBPN-0000";
  im.serial_number = "SN0000001";
  im.hardware_revision = 3;
  im.software_functional = 1;
  im.software_bugfix = 18;
  im.revision_counter = 0;
  im.profile_id = 0x3A00;
  im.im_supported = 0x001E;
  std::array<std::uint8_t, kIm0Size> im_bytes{};
  EXPECT_EQ(encode_im0(im, im_bytes), kIm0Size);
  n = encode_read_response(response_header_for(req, 1), ok, test::kArgsMaximum, record_response_for(rd, 0), im_bytes,
                           buf);
  cap.add(kDrive, kPlc, std::span(buf).first(n));

  // PrmEnd, then the device's ApplicationReady to the controller, then Release.
  ControlBlock prm_end{block_type::kPrmEndReq, test::kArUuid, 1, 0, control_command::kPrmEnd, 0};
  req = test::device_call(Opnum::Control, seq++, order);
  n = encode_control_request(req, test::kArgsMaximum, prm_end, buf);
  cap.add(kPlc, kDrive, std::span(buf).first(n));
  n = encode_control_response(response_header_for(req, 1), ok, test::kArgsMaximum, control_response_for(prm_end), buf);
  cap.add(kDrive, kPlc, std::span(buf).first(n));

  ControlBlock ready{block_type::kApplicationReadyReq, test::kArUuid, 1, 0, control_command::kApplicationReady, 0};
  const RpcHeader dreq = pnio_request_header(make_pnio_object_uuid(test::kController), kPnioControllerInterface,
                                             test::kDeviceActivity, 0, Opnum::Control, order);
  n = encode_control_request(dreq, test::kArgsMaximum, ready, buf);
  cap.add(kDriveClient, kPlcServer, std::span(buf).first(n));
  n = encode_control_response(response_header_for(dreq, 7), ok, test::kArgsMaximum, control_response_for(ready), buf);
  cap.add(kPlcServer, kDriveClient, std::span(buf).first(n));

  ControlBlock release{block_type::kReleaseReq, test::kArUuid, 1, 0, control_command::kRelease, 0};
  req = test::device_call(Opnum::Release, seq++, order);
  n = encode_control_request(req, test::kArgsMaximum, release, buf);
  cap.add(kPlc, kDrive, std::span(buf).first(n));
  n = encode_control_response(response_header_for(req, 1), ok, test::kArgsMaximum, control_response_for(release), buf);
  cap.add(kDrive, kPlc, std::span(buf).first(n));
  return cap.frames;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t c = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++c;
  return c;
}

class PnTshark : public ::testing::TestWithParam<ByteOrder> {};

TEST_P(PnTshark, ConnectToReleaseDissectsCleanly) {
  const std::vector<Bytes> fs = exchange(GetParam());
  ASSERT_EQ(fs.size(), 12U);
  const std::optional<std::string> dissected = drivegate::test::tshark_dissect(fs);
  if (!dissected) GTEST_SKIP() << "tshark not installed (scripts/install-deps.sh)";
  const std::string& out = *dissected;
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.find("Malformed"), std::string::npos) << out;
  EXPECT_EQ(out.find("Exception"), std::string::npos) << out;
  EXPECT_EQ(out.find("[Severity level: Error]"), std::string::npos) << out;
  EXPECT_EQ(out.find("[Severity level: Warning]"), std::string::npos) << out;
  EXPECT_NE(out.find("Frame 12:"), std::string::npos);
  EXPECT_EQ(count(out, "DCE/RPC"), 12U) << out;
  EXPECT_EQ(count(out, "PROFINET IO"), 12U) << out;
  for (const char* field : {"Operation: Connect (0)", "Operation: Write (3)", "Operation: Read (2)",
                            "Operation: Control (4)", "Operation: Release (1)", "ARBlockReq", "IOCRBlockReq",
                            "AlarmCRBlockReq", "ExpectedSubmoduleBlockReq", "ARBlockRes", "IOCRBlockRes",
                            "AlarmCRBlockRes", "IODWriteReqHeader", "IODWriteResHeader", "IODReadReqHeader",
                            "IODReadResHeader", "I&M0", "IODControlReq", "IOXBlockReq", "IODControlRes",
                            "IOXBlockRes", "IODReleaseReq", "IODReleaseRes", "StationName: drivegate",
                            "API: 0x00003a00", "OrderID: AKD-P00306-NBPN-0000", "Command: ParameterEnd", "Command: ApplicationReady", "ControlCommand: 0x0008, Done", "[Request in frame: 11]"}) {
    EXPECT_NE(out.find(field), std::string::npos) << "missing: " << field;
  }
  // Six responses, each with PNIOStatus OK in the NDR part; the write response's header too.
  EXPECT_GE(count(out, "Status: OK"), 6U) << out;
}

// A refused write: the PNIOStatus in the NDR part (an Unsigned32 in the drep's byte order) and
// in the IODWriteResHeader (big-endian like every block) must both read back as DF 80 B6 05.
TEST_P(PnTshark, ErrorStatusReadsBack) {
  const ByteOrder order = GetParam();
  std::array<std::uint8_t, 512> buf{};
  const PnioStatus denied{0xDF, 0x80, 0xB6, 0x05};
  RecordReqHeader wr;
  wr.type = block_type::kWriteReqHeader;
  wr.ar_uuid = test::kArUuid;
  wr.slot = 1;
  wr.subslot = 1;
  wr.index = 0x1000;  // a manufacturer record: index 47 would be dissected as a (short) PROFIdrive request
  wr.record_data_length = 2;
  const RpcHeader req = test::device_call(Opnum::Write, 9, order);
  const std::array<std::uint8_t, 2> two{1, 2};
  std::vector<Bytes> fs;
  std::size_t n = encode_write_request(req, test::kArgsMaximum, wr, two, buf);
  fs.push_back(test::udp_frame(kPlc, kDrive, std::span(buf).first(n), 1));
  n = encode_write_response(response_header_for(req, 1), denied, test::kArgsMaximum, record_response_for(wr, 0, denied),
                            buf);
  fs.push_back(test::udp_frame(kDrive, kPlc, std::span(buf).first(n), 2));
  const std::optional<std::string> dissected = drivegate::test::tshark_dissect(fs);
  if (!dissected) GTEST_SKIP() << "tshark not installed (scripts/install-deps.sh)";
  const std::string& out = *dissected;
  EXPECT_EQ(out.find("Malformed"), std::string::npos) << out;
  EXPECT_EQ(count(out, "ErrorCode: IODWriteRes (0xdf)"), 2U) << out;
  EXPECT_EQ(count(out, "ErrorDecode: PNIORW (0x80)"), 2U) << out;
  EXPECT_EQ(count(out, "ErrorCode1: access: access denied (182)"), 2U) << out;
  EXPECT_EQ(out.find("Unknown ErrorDecode"), std::string::npos) << out;
}

INSTANTIATE_TEST_SUITE_P(Drep, PnTshark, ::testing::Values(ByteOrder::Little, ByteOrder::Big),
                         [](const ::testing::TestParamInfo<ByteOrder>& p) { return p.param == ByteOrder::Little ? "Little" : "Big"; });

}  // namespace
}  // namespace drivegate::profinet
