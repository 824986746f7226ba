// The connectionless DCE/RPC header, the NDR wrapper, faults and PNIOStatus texts against
// byte-exact vectors written from the layouts [DCE 1.1 RPC §12.5.1 "Connectionless PDU header";
// IEC 61158-6-10 §4.10.3.2 (PNIO UUIDs), §5.1.2 (NDR args), §5.2.6 (PNIOStatus)], in both drep
// byte orders, and every decoder on malformed input.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "adapters/profinet/wire/rpc.hpp"
#include "adapters/profinet/wire/rpc_calls.hpp"
#include "adapters/profinet/wire/rpc_status.hpp"
#include "tests/profinet_rpc/hex.hpp"
#include "tests/profinet_rpc/scenario.hpp"

namespace drivegate::profinet {
namespace {

using test::hex;

RpcHeader sample(ByteOrder order) {
  RpcHeader h = test::device_call(Opnum::Connect, 5, order);
  h.fragment_length = 0x0123;
  return h;
}

// DCE 1.1 RPC §12.5.1: offsets 0-7 rpc_vers, ptype, flags1, flags2, drep[3], serial_hi; 8 object,
// 24 interface, 40 activity (UUIDs: u32, u16, u16 in drep order, then 8 octets); 56 server_boot,
// 60 if_vers, 64 seqnum, 68 opnum, 70 ihint, 72 ahint, 74 len, 76 fragnum, 78 auth_proto,
// 79 serial_lo.
const auto kHeaderLittle = hex(
    "04 00 20 00 | 10 00 00 | 00"
    "00 00 A0 DE 97 6C D1 11 82 71 00 01 00 02 12 34"   // object DEA00000-...-0001 0002 1234
    "01 00 A0 DE 97 6C D1 11 82 71 00 A0 24 42 DF 7D"   // interface DEA00001-... (device)
    "04 03 02 01 06 05 08 07 09 0A 0B 0C 0D 0E 0F 10"   // activity
    "00 00 00 00 | 01 00 00 00 | 05 00 00 00"           // boot time, interface version 1, seq 5
    "00 00 | FF FF | FF FF | 23 01 | 00 00 | 00 | 00");  // opnum Connect, hints, len 0x123
const auto kHeaderBig = hex(
    "04 00 20 00 | 00 00 00 | 00"
    "DE A0 00 00 6C 97 11 D1 82 71 00 01 00 02 12 34"
    "DE A0 00 01 6C 97 11 D1 82 71 00 A0 24 42 DF 7D"
    "01 02 03 04 05 06 07 08 09 0A 0B 0C 0D 0E 0F 10"
    "00 00 00 00 | 00 00 00 01 | 00 00 00 05"
    "00 00 | FF FF | FF FF | 01 23 | 00 00 | 00 | 00");

TEST(PnRpc, HeaderLittleEndianBytes) {
  std::array<std::uint8_t, kRpcHeaderSize> out{};
  ASSERT_EQ(encode_rpc_header(sample(ByteOrder::Little), out), kRpcHeaderSize);
  EXPECT_EQ(test::bytes(out), kHeaderLittle);
}

TEST(PnRpc, HeaderBigEndianBytes) {
  std::array<std::uint8_t, kRpcHeaderSize> out{};
  ASSERT_EQ(encode_rpc_header(sample(ByteOrder::Big), out), kRpcHeaderSize);
  EXPECT_EQ(test::bytes(out), kHeaderBig);
}

TEST(PnRpc, HeaderDecodesBothOrders) {
  for (const auto& [bytes, order] : {std::pair{kHeaderLittle, ByteOrder::Little}, std::pair{kHeaderBig, ByteOrder::Big}}) {
    auto d = bytes;
    d.resize(kRpcHeaderSize + 0x123, 0xAB);
    const RpcView v = decode_rpc(d);
    ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
    EXPECT_EQ(v.header, sample(order));
    EXPECT_EQ(v.body.size(), 0x123U);
    EXPECT_EQ(v.body.data(), d.data() + kRpcHeaderSize);  // a view, not a copy
    PnioObject o;
    ASSERT_TRUE(parse_pnio_object_uuid(v.header.object, o));
    EXPECT_EQ(o, test::kDevice);
  }
}

TEST(PnRpc, ObjectUuidLayout) {
  // DEA00000-6C97-11D1-8271-{instance}{device}{vendor} [IEC 61158-6-10 §4.10.3.2.1].
  const Uuid u = make_pnio_object_uuid({0x0102, 0x0304, 0x0506});
  EXPECT_EQ(u.time_low, 0xDEA00000U);
  EXPECT_EQ(u.time_mid, 0x6C97);
  EXPECT_EQ(u.time_hi_and_version, 0x11D1);
  EXPECT_EQ(u.clock_seq_node, (std::array<std::uint8_t, 8>{0x82, 0x71, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06}));
  PnioObject o;
  EXPECT_FALSE(parse_pnio_object_uuid(kPnioDeviceInterface, o));
}

TEST(PnRpc, HeaderMalformed) {
  EXPECT_EQ(decode_rpc(std::span(kHeaderLittle).first(79)).error, WireError::Truncated);
  auto d = kHeaderLittle;  // fragment length 0x123 but no body
  EXPECT_EQ(decode_rpc(d).error, WireError::FragmentLengthBeyondData);
  d[74] = 0;
  d[75] = 0;
  EXPECT_EQ(decode_rpc(d).error, WireError::None);
  auto bad = d;
  bad[0] = 5;  // connection-oriented RPC is version 5
  EXPECT_EQ(decode_rpc(bad).error, WireError::BadRpcVersion);
  bad = d;
  bad[1] = 11;
  EXPECT_EQ(decode_rpc(bad).error, WireError::UnknownPacketType);
  bad = d;
  bad[4] = 0x20;  // integer representation 2
  EXPECT_EQ(decode_rpc(bad).error, WireError::UnsupportedDrep);
  bad = d;
  bad[4] = 0x11;  // EBCDIC
  EXPECT_EQ(decode_rpc(bad).error, WireError::UnsupportedDrep);
  RpcHeader h = sample(ByteOrder::Little);
  h.drep_char = 1;
  std::array<std::uint8_t, kRpcHeaderSize> out{};
  EXPECT_EQ(encode_rpc_header(h, out), 0U);
  EXPECT_EQ(encode_rpc_header(sample(ByteOrder::Little), std::span(out).first(79)), 0U);
}

TEST(PnRpc, NdrRequestBytesAndChecks) {
  // ArgsMaximum 16696 (4138h), ArgsLength 4, MaximumCount 16696, Offset 0, ActualCount 4, blocks.
  std::array<std::uint8_t, 128> buf{};
  const auto area = pnio_blocks_area(buf);
  area[0] = 0xB1;
  area[1] = 0xB2;
  area[2] = 0xB3;
  area[3] = 0xB4;
  const RpcHeader h = test::device_call(Opnum::Read, 7, ByteOrder::Little);
  ASSERT_EQ(finish_pnio_request(h, 16696, 4, buf), kPnioBlocksOffset + 4);
  EXPECT_EQ(test::bytes(std::span(buf).subspan(kRpcHeaderSize, 24)),
            hex("38 41 00 00 | 04 00 00 00 | 38 41 00 00 | 00 00 00 00 | 04 00 00 00 | B1 B2 B3 B4"));
  EXPECT_EQ(buf[74], 24);  // fragment length: NDR + blocks
  const PnioRequestView v = decode_pnio_request(std::span(buf).first(kPnioBlocksOffset + 4));
  ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
  EXPECT_EQ(v.ndr.args_maximum, 16696U);
  EXPECT_EQ(v.ndr.blocks.size(), 4U);
  EXPECT_EQ(v.ndr.blocks[3], 0xB4);

  const auto big = hex("00 00 41 38 | 00 00 00 04 | 00 00 41 38 | 00 00 00 00 | 00 00 00 04 | B1 B2 B3 B4");
  EXPECT_EQ(decode_ndr_request(big, ByteOrder::Big).error, WireError::None);
  EXPECT_EQ(decode_ndr_request(std::span(big).first(19), ByteOrder::Big).error, WireError::Truncated);
  EXPECT_EQ(decode_ndr_request(std::span(big).first(23), ByteOrder::Big).error, WireError::ArgsLengthBeyondData);
  auto lying = big;
  lying[19] = 3;  // ActualCount 3 != ArgsLength 4
  EXPECT_EQ(decode_ndr_request(lying, ByteOrder::Big).error, WireError::NdrCountsInconsistent);
  lying = big;
  lying[2] = 0;
  lying[3] = 2;  // ArgsMaximum 2 < ArgsLength 4
  EXPECT_EQ(decode_ndr_request(lying, ByteOrder::Big).error, WireError::NdrCountsInconsistent);
  lying = big;
  lying[15] = 0x40;  // Offset past MaximumCount
  lying[14] = 0x41;
  EXPECT_EQ(decode_ndr_request(lying, ByteOrder::Big).error, WireError::NdrCountsInconsistent);
}

TEST(PnRpc, NdrResponseBytesAndChecks) {
  std::array<std::uint8_t, 128> buf{};
  const RpcHeader req = test::device_call(Opnum::Write, 7, ByteOrder::Big);
  const PnioStatus st{0xDF, 0x80, 0xB0, 0x00};
  ASSERT_EQ(finish_pnio_response(response_header_for(req, 9), st, 16696, 0, buf), kPnioBlocksOffset);
  // PNIOStatus is an Unsigned32 in the NDR part, ErrorCode on top; big-endian drep here.
  EXPECT_EQ(test::bytes(std::span(buf).subspan(kRpcHeaderSize, kNdrHeaderSize)),
            hex("DF 80 B0 00 | 00 00 00 00 | 00 00 41 38 | 00 00 00 00 | 00 00 00 00"));
  EXPECT_EQ(buf[1], 2);      // response
  EXPECT_EQ(buf[2], 0x0A);   // last fragment, no fack
  EXPECT_EQ(buf[59], 9);     // server boot time, big-endian
  const PnioResponseView v = decode_pnio_response(std::span(buf).first(kPnioBlocksOffset));
  ASSERT_EQ(v.error, WireError::None);
  EXPECT_EQ(v.ndr.status, st);
  EXPECT_EQ(v.header.sequence_number, 7U);
  EXPECT_EQ(v.header.opnum, 3);
  // The request decoder refuses a response and the other way round.
  EXPECT_EQ(decode_pnio_request(std::span(buf).first(kPnioBlocksOffset)).error, WireError::UnexpectedPacketType);
  EXPECT_EQ(decode_ndr_response(std::span(buf).subspan(kRpcHeaderSize, 19), ByteOrder::Big).error, WireError::Truncated);
  auto lying = test::bytes(std::span(buf).subspan(kRpcHeaderSize, kNdrHeaderSize));
  lying[7] = 1;  // ArgsLength 1, nothing follows
  EXPECT_EQ(decode_ndr_response(lying, ByteOrder::Big).error, WireError::ArgsLengthBeyondData);
  lying.push_back(0);
  EXPECT_EQ(decode_ndr_response(lying, ByteOrder::Big).error, WireError::NdrCountsInconsistent);

  // A little-endian drep reverses the status octets (Wireshark's dissect_PNIO_status reads it so).
  const RpcHeader le_req = test::device_call(Opnum::Write, 7, ByteOrder::Little);
  ASSERT_EQ(finish_pnio_response(response_header_for(le_req, 9), st, 16696, 0, buf), kPnioBlocksOffset);
  EXPECT_EQ(test::bytes(std::span(buf).subspan(kRpcHeaderSize, kNdrHeaderSize)),
            hex("00 B0 80 DF | 00 00 00 00 | 38 41 00 00 | 00 00 00 00 | 00 00 00 00"));
  EXPECT_EQ(decode_pnio_response(std::span(buf).first(kPnioBlocksOffset)).ndr.status, st);
  EXPECT_EQ(status_to_u32(st), 0xDF80B000U);
  EXPECT_EQ(status_from_u32(0xDB810104U), (PnioStatus{0xDB, 0x81, 0x01, 0x04}));
}

TEST(PnRpc, NotPnioRefused) {
  std::array<std::uint8_t, 128> buf{};
  RpcHeader h = test::device_call(Opnum::Read, 1);
  h.interface.time_low = 0x12345678;
  ASSERT_NE(finish_pnio_request(h, 100, 0, buf), 0U);
  EXPECT_EQ(decode_pnio_request(std::span(buf).first(kPnioBlocksOffset)).error, WireError::UnexpectedInterface);
  h = test::device_call(Opnum::Read, 1);
  h.opnum = 6;
  ASSERT_NE(finish_pnio_request(h, 100, 0, buf), 0U);
  EXPECT_EQ(decode_pnio_request(std::span(buf).first(kPnioBlocksOffset)).error, WireError::UnexpectedOpnum);
  // A too-small buffer and blocks beyond ArgsMaximum are refused by the composer.
  EXPECT_EQ(finish_pnio_request(h, 100, 0, std::span(buf).first(99)), 0U);
  EXPECT_EQ(finish_pnio_request(h, 2, 4, buf), 0U);
}

TEST(PnRpc, FaultStatus) {
  const auto le = hex("03 00 01 1C");
  const RpcFaultView f = decode_rpc_fault(le, ByteOrder::Little);
  ASSERT_EQ(f.error, WireError::None);
  EXPECT_EQ(f.status, 0x1C010003U);
  EXPECT_EQ(nca_status_text(f.status), "nca_s_unk_if: unknown interface");
  EXPECT_EQ(decode_rpc_fault(hex("1C 01 00 02"), ByteOrder::Big).status, 0x1C010002U);
  EXPECT_EQ(decode_rpc_fault(hex("1C 01 00"), ByteOrder::Big).error, WireError::Truncated);
  EXPECT_EQ(nca_status_text(0x12345678), "unknown NCA status");
}

TEST(PnRpc, PacketTypeAndOpnumNames) {
  EXPECT_EQ(to_string(PacketType::Reject), "reject");
  EXPECT_EQ(to_string(PacketType::Working), "working");
  EXPECT_EQ(to_string(Opnum::ReadImplicit), "ReadImplicit");
  EXPECT_EQ(to_string(WireError::CountBeyondData), "a count needs more bytes than the block holds");
}

std::string text(const PnioStatus& s) {
  std::array<char, 160> buf{};
  return std::string(describe(s, buf));
}

TEST(PnStatus, Texts) {
  EXPECT_EQ(text({}), "OK");
  // IEC 61158-6-10 ErrorCode1 = 1 (ARBlockReq), ErrorCode2 = 4 (ARType)
  EXPECT_EQ(text({0xDB, 0x81, 0x01, 0x04}),
            "IODConnectRes PNIO: Connect: Faulty ARBlockReq: Error in Parameter ARType (DB 81 01 04)");
  EXPECT_EQ(text({0xDB, 0x81, 0x02, 0x0B}),
            "IODConnectRes PNIO: Connect: Faulty IOCRBlockReq: Error in Parameter ReductionRatio (DB 81 02 0B)");
  EXPECT_EQ(text({0xDB, 0x81, 0x03, 0x07}),
            "IODConnectRes PNIO: Connect: Faulty ExpectedSubmoduleBlockReq: Error in Parameter ModuleIdentNumber "
            "(DB 81 03 07)");
  EXPECT_EQ(text({0xDB, 0x81, 0x04, 0x08}),
            "IODConnectRes PNIO: Connect: Faulty AlarmCRBlockReq: Error in Parameter RTARetries (DB 81 04 08)");
  EXPECT_EQ(text({0xDB, 0x81, 0x40, 0x04}), "IODConnectRes PNIO: CMRPC: Out of AR Resources (DB 81 40 04)");
  EXPECT_EQ(text({0xDD, 0x81, 0x14, 0x06}),
            "IODControlRes PNIO: IODControl: Faulty ControlBlockConnect: Error in Parameter SessionKey (DD 81 14 06)");
  EXPECT_EQ(text({0xDC, 0x81, 0x28, 0x08}),
            "IODReleaseRes PNIO: Release: Faulty ReleaseBlock: Error in Parameter ControlCommand (DC 81 28 08)");
  EXPECT_EQ(text({0xDE, 0x80, 0xB0, 0x00}), "IODReadRes PNIORW: access: invalid index (DE 80 B0 00)");
  EXPECT_EQ(text({0xDF, 0x80, 0xB6, 0x12}), "IODWriteRes PNIORW: access: access denied (DF 80 B6 12)");
  EXPECT_EQ(text({0xDF, 0x80, 0xC2, 0x00}), "IODWriteRes PNIORW: resource: resource busy (DF 80 C2 00)");
  EXPECT_EQ(text({0xCF, 0x81, 0xFD, 0x05}), "RTA error PNIO: RTA protocol error: AR consumer DHT/WDT expired (CF 81 FD 05)");
  // Unknown combinations still say what is known and give the octets.
  EXPECT_EQ(text({0xDB, 0x81, 0x63, 0x00}), "IODConnectRes PNIO: unknown error (DB 81 63 00)");
  EXPECT_EQ(text({0x12, 0x82, 0x01, 0x02}), "unknown error code manufacturer specific: unknown error (12 82 01 02)");
  // Cut at the buffer's end, no overrun.
  std::array<char, 8> small{};
  EXPECT_EQ(describe({0xDB, 0x81, 0x01, 0x04}, small), "IODConne");
}

}  // namespace
}  // namespace drivegate::profinet
