// CmServer on its own: what the simulated device does with calls a well-behaved controller does
// not make (a second Connect of the same AR, fragments, pings, other interfaces).
#include <gtest/gtest.h>

#include "tests/profinet_cm/cm_harness.hpp"

namespace drivegate::profinet {
namespace {

using namespace test;

RpcHeader only_answer(CmOutbox& out) {
  EXPECT_EQ(out.size(), 1U);
  const RpcHeader h = decode_rpc(out.front().view()).header;
  return h;
}

TEST(PnCmServer, ConnectOfTheRunningArAbortsItAndStartsOver) {
  Bench b;
  b.start();
  ASSERT_EQ(b.drive->state(), CmServerState::DataExchange);
  // The controller restarted: same AR UUID, next session key, a new activity.
  b.config.connect.ar.session_key = 2;
  b.config.activity.time_low ^= 0xFF;
  b.rebuild_client();
  b.start();
  EXPECT_EQ(b.drive->counters().aborts, 1U);
  EXPECT_EQ(b.drive->abort_reason(), "a new Connect for the running AR");
  EXPECT_EQ(b.drive->counters().connects, 2U);
  EXPECT_EQ(b.drive->session_key(), 2);
  EXPECT_EQ(b.drive->state(), CmServerState::DataExchange);
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange) << b.plc->reason();
}

TEST(PnCmServer, FragmentedRequestIsRejected) {
  Bench b;
  b.plc->start(b.now, b.plc_out);
  std::vector<std::uint8_t> req(b.plc_out.front().view().begin(), b.plc_out.front().view().end());
  b.plc_out.pop();
  req[2] |= rpc_flag1::kFragment;
  b.drive->on_datagram(req, {kPlcIp, kPlcClientPort}, CmSocket::Server, b.now, b.drive_out);
  const RpcHeader h = only_answer(b.drive_out);
  EXPECT_EQ(h.packet_type, static_cast<std::uint8_t>(PacketType::Reject));
  const RpcView v = decode_rpc(b.drive_out.front().view());
  EXPECT_EQ(decode_rpc_fault(v.body, v.header.order).status, nca_status::kProtoError);
  EXPECT_EQ(b.drive->state(), CmServerState::NoAr);
  // The client reads the reject as the end of its Connect.
  b.plc->on_datagram(b.drive_out.front().view(), {kDriveIp, kRpcUdpPort}, CmSocket::Client, b.now, b.plc_out);
  EXPECT_EQ(b.plc->reason(), "Connecting: Connect: RPC reject 0x1C01000B nca_s_proto_error: protocol error");
}

TEST(PnCmServer, PingIsAnsweredWithTheResponseOrNocall) {
  Bench b;
  b.plc->start(b.now, b.plc_out);
  const std::vector<std::uint8_t> req(b.plc_out.front().view().begin(), b.plc_out.front().view().end());
  b.plc_out.pop();
  RpcHeader ping = decode_rpc(req).header;
  ping.packet_type = static_cast<std::uint8_t>(PacketType::Ping);
  ping.fragment_length = 0;
  std::array<std::uint8_t, kRpcHeaderSize> p{};
  ASSERT_EQ(encode_rpc_header(ping, p), kRpcHeaderSize);
  b.drive->on_datagram(p, {kPlcIp, kPlcClientPort}, CmSocket::Server, b.now, b.drive_out);
  EXPECT_EQ(only_answer(b.drive_out).packet_type, static_cast<std::uint8_t>(PacketType::Nocall));
  b.drive_out.pop();
  b.drive->on_datagram(req, {kPlcIp, kPlcClientPort}, CmSocket::Server, b.now, b.drive_out);
  const std::vector<std::uint8_t> res(b.drive_out.front().view().begin(), b.drive_out.front().view().end());
  b.drive_out.pop();
  b.drive->on_datagram(p, {kPlcIp, kPlcClientPort}, CmSocket::Server, b.now, b.drive_out);
  ASSERT_EQ(b.drive_out.size(), 1U);
  EXPECT_TRUE(std::ranges::equal(b.drive_out.front().view(), res)) << "the cached Connect response again";
  EXPECT_EQ(b.drive->counters().connects, 1U);
}

TEST(PnCmServer, OtherInterfaceAndReadImplicitAreRejected) {
  Bench b;
  b.plc->start(b.now, b.plc_out);
  std::vector<std::uint8_t> req(b.plc_out.front().view().begin(), b.plc_out.front().view().end());
  b.plc_out.pop();
  const RpcHeader h = decode_rpc(req).header;
  RpcHeader other = h;
  other.interface = kPnioSupervisorInterface;
  ASSERT_EQ(encode_rpc_header(other, req), kRpcHeaderSize);
  b.drive->on_datagram(req, {kPlcIp, kPlcClientPort}, CmSocket::Server, b.now, b.drive_out);
  RpcView v = decode_rpc(b.drive_out.front().view());
  EXPECT_EQ(v.header.packet_type, static_cast<std::uint8_t>(PacketType::Reject));
  EXPECT_EQ(decode_rpc_fault(v.body, v.header.order).status, nca_status::kUnknownInterface);
  b.drive_out.pop();
  RpcHeader implicit = h;
  implicit.sequence_number = 7;
  implicit.opnum = static_cast<std::uint16_t>(Opnum::ReadImplicit);
  ASSERT_EQ(encode_rpc_header(implicit, req), kRpcHeaderSize);
  b.drive->on_datagram(req, {kPlcIp, kPlcClientPort}, CmSocket::Server, b.now, b.drive_out);
  v = decode_rpc(b.drive_out.front().view());
  EXPECT_EQ(decode_rpc_fault(v.body, v.header.order).status, nca_status::kOpRangeError);
  EXPECT_EQ(b.drive->counters().rpc.refused, 2U);
}

TEST(PnCmServer, RecordsWithoutTheArAreRefused) {
  Bench b;
  b.start();
  const CmRecordId r = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  b.run_for(20ms);
  ASSERT_EQ(b.replies.count_of(r), 1);
  // The device lost the AR (restarted): the controller's reads name an unknown AR.
  b.drive = std::make_unique<CmServer>(drive_config(), b.app);
  const CmRecordId again = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  b.run_for(20ms);
  const auto k = b.replies.find(again);
  ASSERT_EQ(k.id, again);
  EXPECT_EQ(k.outcome, CmRecordOutcome::Refused);
  EXPECT_EQ(k.text, "IODReadRes PNIO: CMRPC: AR UUID unknown (DE 81 40 05)");
}

}  // namespace
}  // namespace drivegate::profinet
