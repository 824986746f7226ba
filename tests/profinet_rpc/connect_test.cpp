// Whole Connect datagrams [IEC 61158-6-10 §5.1.2 IODConnectReq/Res]: the composed request is the
// RPC header, the NDR wrapper and exactly the block vectors of blocks_test.cpp and
// blocks_submodule_test.cpp one after the other; the response walker reads each block, reports a
// ModuleDiffBlock, and refuses a response that lies.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "adapters/profinet/wire/rpc_calls.hpp"
#include "adapters/profinet/wire/rpc_connect.hpp"
#include "tests/profinet_rpc/hex.hpp"
#include "tests/profinet_rpc/scenario.hpp"

namespace drivegate::profinet {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes connect_request(ByteOrder order) {
  std::array<std::uint8_t, 1464> buf{};
  const test::Scenario s;
  const std::size_t n = encode_connect_request(test::device_call(Opnum::Connect, 3, order), test::kArgsMaximum,
                                               s.connect(), buf);
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
}

TEST(PnConnect, RequestIsHeaderNdrAndTheBlocks) {
  for (const ByteOrder order : {ByteOrder::Little, ByteOrder::Big}) {
    const Bytes d = connect_request(order);
    // 80 + 20 + AR 67 + IOCR 80 + 80 + AlarmCR 26 + Expected 36 + 42 = 431
    ASSERT_EQ(d.size(), 431U);
    const PnioRequestView v = decode_pnio_request(d);
    ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
    EXPECT_EQ(v.header.order, order);
    EXPECT_EQ(v.header.opnum, 0);
    EXPECT_EQ(v.header.fragment_length, 351);
    EXPECT_EQ(v.ndr.args_length, 331U);
    EXPECT_EQ(v.ndr.args_maximum, test::kArgsMaximum);
    // The blocks are big-endian whatever the drep: the same bytes in both orders.
    const Bytes little = connect_request(ByteOrder::Little);
    EXPECT_EQ(test::bytes(v.ndr.blocks), test::bytes(std::span(little).subspan(100)));
    BlockWalker w(v.ndr.blocks);
    BlockView b;
    std::vector<std::uint16_t> types;
    while (w.next(b)) types.push_back(b.header.type);
    EXPECT_EQ(w.error(), WireError::None);
    EXPECT_EQ(types, (std::vector<std::uint16_t>{0x0101, 0x0102, 0x0102, 0x0103, 0x0104, 0x0104}));
  }
  const Bytes d = connect_request(ByteOrder::Little);
  const auto blocks = std::span(d).subspan(100);
  const ArBlockReqView ar = decode_ar_block_req(blocks);
  ASSERT_EQ(ar.error, WireError::None);
  EXPECT_EQ(ar.block.station_name, "drivegate");
  const IocrBlockReqView out = decode_iocr_block_req(blocks.subspan(ar.size + 80));
  ASSERT_EQ(out.error, WireError::None);
  EXPECT_EQ(out.params.type, iocr_type::kOutput);  // forced by the composer
  EXPECT_EQ(out.params.frame_id, 0xC002);
}

TEST(PnConnect, DeviceSideDecode) {
  const test::Scenario s;
  for (const ByteOrder order : {ByteOrder::Little, ByteOrder::Big}) {
    const Bytes d = connect_request(order);
    const ConnectRequestView v = decode_connect_request(d);
    ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
    EXPECT_EQ(v.args_maximum, test::kArgsMaximum);
    EXPECT_EQ(v.ar.block.station_name, "drivegate");
    ASSERT_EQ(v.iocr_count, 2U);
    EXPECT_EQ(v.iocrs[0].params.type, iocr_type::kInput);
    EXPECT_EQ(v.iocrs[1].params.reduction_ratio, 16);
    EXPECT_EQ(v.alarm_cr.block, AlarmCrBlockReq{});
    ASSERT_EQ(v.expected_count, 2U);
    ExpectedSubmoduleReader r(v.expected[1]);
    ExpectedEntry e;
    ASSERT_TRUE(r.next(e));
    EXPECT_EQ(e.submodule, s.tg_subs[0]);
  }
  // Without its AlarmCRBlockReq (the last 26 + 78 bytes rebuilt without it): missing.
  std::array<std::uint8_t, 1464> buf{};
  const ConnectRequest c = s.connect();
  auto area = pnio_blocks_area(buf);
  std::size_t used = encode_ar_block_req(c.ar, area);
  used += encode_iocr_block_req(c.input, c.input_apis, area.subspan(used));
  std::size_t n = finish_pnio_request(test::device_call(Opnum::Connect, 1), test::kArgsMaximum, used, buf);
  EXPECT_EQ(decode_connect_request(std::span(buf).first(n)).error, WireError::MissingBlock);
  // A second AR block.
  used += encode_ar_block_req(c.ar, area.subspan(used));
  n = finish_pnio_request(test::device_call(Opnum::Connect, 1), test::kArgsMaximum, used, buf);
  EXPECT_EQ(decode_connect_request(std::span(buf).first(n)).error, WireError::DuplicateBlock);
  // A lying count inside the IOCR (NumberOfAPIs at block offset 45).
  Bytes d = connect_request(ByteOrder::Little);
  d[100 + 67 + 45] = 9;
  EXPECT_EQ(decode_connect_request(d).error, WireError::CountBeyondData);
  // Every cut.
  const Bytes good = connect_request(ByteOrder::Big);
  for (std::size_t k = 0; k < good.size(); ++k) {
    EXPECT_NE(decode_connect_request(std::span(good).first(k)).error, WireError::None) << k;
  }
}

TEST(PnConnect, RequestRefusals) {
  std::array<std::uint8_t, 1464> buf{};
  const test::Scenario s;
  EXPECT_EQ(encode_connect_request(test::device_call(Opnum::Read, 3), test::kArgsMaximum, s.connect(), buf), 0U);
  EXPECT_EQ(encode_connect_request(test::device_call(Opnum::Connect, 3), test::kArgsMaximum, s.connect(),
                                   std::span(buf).first(430)),
            0U);
  EXPECT_EQ(encode_connect_request(test::device_call(Opnum::Connect, 3), 300, s.connect(), buf), 0U);  // > ArgsMaximum
}

struct Response {
  Bytes bytes;
};

Response connect_response(const PnioStatus& status, bool with_diff, ByteOrder order = ByteOrder::Little) {
  std::array<std::uint8_t, 1464> buf{};
  const std::array<IocrBlockRes, 2> iocrs{{{iocr_type::kInput, 1, 0xC001}, {iocr_type::kOutput, 2, 0xC012}}};
  const std::array<ModuleDiffSubmodule, 1> subs{{{1, 1, 0x8080}}};  // application ready pending
  const std::array<ModuleDiffModule, 1> mods{{{1, test::kTelegram1Module, ModuleState::ProperModule, subs}}};
  const std::array<ModuleDiffApi, 1> apis{{{test::kProfidriveApi, mods}}};
  ConnectResponse c;
  c.ar = {ar_type::kIocarSingle, test::kArUuid, 1, test::kDeviceMac, kEtherTypePnio};
  c.iocrs = iocrs;
  if (with_diff) c.module_diff = apis;
  const RpcHeader h = response_header_for(test::device_call(Opnum::Connect, 3, order), 77);
  const std::size_t n = encode_connect_response(h, status, test::kArgsMaximum, c, buf);
  return {Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n))};
}

TEST(PnConnect, ResponseWalk) {
  for (const ByteOrder order : {ByteOrder::Little, ByteOrder::Big}) {
    const Response r = connect_response({}, true, order);
    const ConnectResponseView v = decode_connect_response(r.bytes);
    ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
    EXPECT_TRUE(v.status.ok());
    EXPECT_EQ(v.header.server_boot_time, 77U);
    ASSERT_TRUE(v.has_ar);
    EXPECT_EQ(v.ar.responder_mac, test::kDeviceMac);
    ASSERT_EQ(v.iocr_count, 2U);
    ASSERT_NE(v.iocr(iocr_type::kOutput, 2), nullptr);
    EXPECT_EQ(v.iocr(iocr_type::kOutput, 2)->frame_id, 0xC012);
    EXPECT_EQ(v.iocr(iocr_type::kOutput, 1), nullptr);
    EXPECT_TRUE(v.has_alarm_cr);
    EXPECT_EQ(v.alarm_cr.max_alarm_data_length, 200);
    ASSERT_TRUE(v.has_module_diff);
    std::array<char, 256> text{};
    EXPECT_EQ(std::string(module_diff_report(v.module_diff, test::Scenario{}.expected, text)),
              "slot 1 subslot 1 (API 0x00003A00): application ready pending");
    EXPECT_EQ(v.other_blocks, 0U);
  }
  const ConnectResponseView plain = decode_connect_response(connect_response({}, false).bytes);
  ASSERT_EQ(plain.error, WireError::None);
  EXPECT_FALSE(plain.has_module_diff);
}

TEST(PnConnect, ErrorResponseWithoutBlocks) {
  // A device refusing the AR answers the PNIOStatus and no blocks.
  std::array<std::uint8_t, 128> buf{};
  const PnioStatus refused{0xDB, 0x81, 0x03, 0x07};
  const RpcHeader h = response_header_for(test::device_call(Opnum::Connect, 3), 1);
  const std::size_t n = finish_pnio_response(h, refused, test::kArgsMaximum, 0, buf);
  const ConnectResponseView v = decode_connect_response(std::span(buf).first(n));
  ASSERT_EQ(v.error, WireError::None);
  EXPECT_EQ(v.status, refused);
  EXPECT_FALSE(v.has_ar);
  std::array<char, 160> text{};
  EXPECT_EQ(std::string(describe(v.status, text)),
            "IODConnectRes PNIO: Connect: Faulty ExpectedSubmoduleBlockReq: Error in Parameter ModuleIdentNumber "
            "(DB 81 03 07)");
  // The same with status OK is missing its ARBlockRes.
  const std::size_t m = finish_pnio_response(h, {}, test::kArgsMaximum, 0, buf);
  EXPECT_EQ(decode_connect_response(std::span(buf).first(m)).error, WireError::MissingBlock);
}

TEST(PnConnect, ResponseMalformed) {
  const Bytes good = connect_response({}, true).bytes;
  // Every cut: never a success.
  for (std::size_t n = 0; n < good.size(); ++n) {
    EXPECT_NE(decode_connect_response(std::span(good).first(n)).error, WireError::None) << n;
  }
  // A lying ModuleDiff count inside (NumberOfModules at offset 100 + 34 + 12 + 12 + 12 + 12).
  Bytes b = good;
  b[100 + 34 + 24 + 12 + 13] = 2;
  EXPECT_EQ(decode_connect_response(b).error, WireError::CountBeyondData);
  // A block length running past ArgsLength, and one reaching into the next block.
  b = good;
  b[100 + 2] = 0x7F;
  EXPECT_EQ(decode_connect_response(b).error, WireError::BlockLengthBeyondData);
  b = good;
  b[100 + 3] = 0x40;
  EXPECT_EQ(decode_connect_response(b).error, WireError::BlockLengthMismatch);
  // A second ARBlockRes.
  std::array<std::uint8_t, 1464> buf{};
  auto area = pnio_blocks_area(buf);
  const ArBlockRes ar{ar_type::kIocarSingle, test::kArUuid, 1, test::kDeviceMac, kEtherTypePnio};
  std::size_t used = encode_ar_block_res(ar, area);
  used += encode_ar_block_res(ar, area.subspan(used));
  const RpcHeader h = response_header_for(test::device_call(Opnum::Connect, 3), 1);
  std::size_t n = finish_pnio_response(h, {}, test::kArgsMaximum, used, buf);
  EXPECT_EQ(decode_connect_response(std::span(buf).first(n)).error, WireError::DuplicateBlock);
  // More IOCRBlockRes than the view holds.
  used = encode_ar_block_res(ar, area);
  for (std::size_t i = 0; i <= kMaxConnectIocrs; ++i) {
    used += encode_iocr_block_res({iocr_type::kInput, static_cast<std::uint16_t>(i), 0xC000}, area.subspan(used));
  }
  n = finish_pnio_response(h, {}, test::kArgsMaximum, used, buf);
  EXPECT_EQ(decode_connect_response(std::span(buf).first(n)).error, WireError::TooManyBlocks);
  // Not a Connect: a Read response.
  const RpcHeader rh = response_header_for(test::device_call(Opnum::Read, 3), 1);
  n = finish_pnio_response(rh, {}, test::kArgsMaximum, 0, buf);
  EXPECT_EQ(decode_connect_response(std::span(buf).first(n)).error, WireError::UnexpectedOpnum);
  // A request is not a response.
  EXPECT_EQ(decode_connect_response(connect_request(ByteOrder::Little)).error, WireError::UnexpectedPacketType);
}

}  // namespace
}  // namespace drivegate::profinet
