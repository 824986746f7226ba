// The block header, walking blocks, and the AR, IOCR and AlarmCR blocks against byte-exact vectors
// written from IEC 61158-6-10 §5.2.1 (BlockHeader), §5.2.2.1 (ARBlockReq/Res), §5.2.2.2
// (IOCRBlockReq/Res), §5.2.2.3 (AlarmCRBlockReq/Res), all big-endian; and each decoder on
// truncated, lying and inconsistent input.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "adapters/profinet/wire/blocks.hpp"
#include "tests/profinet_rpc/hex.hpp"
#include "tests/profinet_rpc/scenario.hpp"

namespace drivegate::profinet {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

// ARBlockReq: type 0101h, length 63 (2 version octets + 52 fixed + 9 name), version 1.0, ARType 1,
// ARUUID, SessionKey 1, CMInitiatorMacAdd, CMInitiatorObjectUUID, ARProperties 11h (state active,
// parameterization server = CM initiator), timeout factor 600, UDP RT port 8892h, name.
const Bytes kArReq = hex(
    "01 01 | 00 3F | 01 00"
    "00 01 | 11 22 33 44 55 66 77 88 99 AA BB CC DD EE FF 00 | 00 01 | 02 00 00 00 00 01"
    "DE A0 00 00 6C 97 11 D1 82 71 00 01 00 00 12 34 | 00 00 00 11 | 02 58 | 88 92"
    "00 09 | 64 72 69 76 65 67 61 74 65");

// IOCRBlockReq (input CR of scenario.hpp): length 76.
const Bytes kIocrReq = hex(
    "01 02 | 00 4C | 01 00"
    "00 01 | 00 01 | 88 92 | 00 00 00 01 | 00 28 | C0 01 | 00 20 | 00 10 | 00 01 | 00 00 | FF FF FF FF"
    "00 03 | 00 03 | C0 00 | 00 00 00 00 00 00 | 00 02"
    "00 00 00 00 | 00 01 | 00 00 00 01 00 00 | 00 00"                         // API 0: DAP data object
    "00 00 3A 00 | 00 01 | 00 01 00 01 00 01 | 00 01 | 00 01 00 01 00 06");  // API 3A00h: object, IOCS

const Bytes kAlarmReq = hex("01 03 | 00 16 | 01 00 | 00 01 | 88 92 | 00 00 00 00 | 00 01 | 00 03 | 00 01 | 00 C8 | C0 00 | A0 00");
const Bytes kArRes = hex(
    "81 01 | 00 1E | 01 00 | 00 01 | 11 22 33 44 55 66 77 88 99 AA BB CC DD EE FF 00 | 00 01 | 02 00 00 00 00 02 | 88 92");
const Bytes kIocrRes = hex("81 02 | 00 08 | 01 00 | 00 01 | 00 01 | C0 01");
const Bytes kAlarmRes = hex("81 03 | 00 08 | 01 00 | 00 01 | 00 01 | 00 C8");

template <typename Encode>
Bytes encoded(Encode&& e) {
  std::array<std::uint8_t, 512> buf{};
  const std::size_t n = e(std::span<std::uint8_t>(buf));
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
}

// The shared malformed cases for a block of fixed size: every truncation, a length below the
// fixed part, a length beyond the data, a wrong type, a wrong version, and one byte too many.
template <typename Decode>
void malformed_fixed(const Bytes& good, Decode&& decode) {
  for (std::size_t n = 0; n < good.size(); ++n) {
    const WireError e = decode(std::span(good).first(n)).error;
    EXPECT_TRUE(e == WireError::Truncated || e == WireError::BlockLengthBeyondData) << n << ": " << to_string(e);
  }
  Bytes b = good;
  b[2] = 0;
  b[3] = 1;
  EXPECT_EQ(decode(b).error, WireError::BlockLengthTooShort);
  b = good;
  b[3] = static_cast<std::uint8_t>(b[3] - 1);
  EXPECT_EQ(decode(b).error, WireError::BlockLengthTooShort);
  b = good;
  b[3] = static_cast<std::uint8_t>(b[3] + 1);
  EXPECT_EQ(decode(b).error, WireError::BlockLengthBeyondData);
  b.push_back(0);
  EXPECT_EQ(decode(b).error, WireError::BlockLengthMismatch);
  b = good;
  b[1] ^= 0x40;
  EXPECT_EQ(decode(b).error, WireError::WrongBlockType);
  b = good;
  b[4] = 2;
  EXPECT_EQ(decode(b).error, WireError::UnsupportedBlockVersion);
}

TEST(PnBlocks, HeaderAndWalker) {
  Bytes two = kIocrRes;
  two.insert(two.end(), kAlarmRes.begin(), kAlarmRes.end());
  BlockWalker w(two);
  BlockView b;
  ASSERT_TRUE(w.next(b));
  EXPECT_EQ(b.header, (BlockHeader{0x8102, 8, 1, 0}));
  EXPECT_EQ(b.block.size(), 12U);
  EXPECT_EQ(b.body.size(), 6U);
  EXPECT_EQ(block_type_name(b.header.type), "IOCRBlockRes");
  ASSERT_TRUE(w.next(b));
  EXPECT_EQ(b.header.type, 0x8103);
  EXPECT_FALSE(w.next(b));
  EXPECT_EQ(w.error(), WireError::None);
  two.push_back(0x81);  // a stray byte: an unreadable header
  BlockWalker bad(two);
  while (bad.next(b)) {
  }
  EXPECT_EQ(bad.error(), WireError::Truncated);
  EXPECT_EQ(decode_block(hex("81 02 00 01 01")).error, WireError::Truncated);
  EXPECT_EQ(decode_block(hex("81 02 00 01 01 00")).error, WireError::BlockLengthTooShort);
  EXPECT_EQ(decode_block(hex("81 02 00 03 01 00")).error, WireError::BlockLengthBeyondData);
}

TEST(PnBlocks, ArBlockReq) {
  const test::Scenario s;
  const ConnectRequest c = s.connect();
  EXPECT_EQ(encoded([&](auto o) { return encode_ar_block_req(c.ar, o); }), kArReq);
  const ArBlockReqView v = decode_ar_block_req(kArReq);
  ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
  EXPECT_EQ(v.size, kArReq.size());
  EXPECT_EQ(v.block.ar_uuid, test::kArUuid);
  EXPECT_EQ(v.block.initiator_mac, test::kControllerMac);
  EXPECT_EQ(v.block.properties, 0x11U);
  EXPECT_EQ(v.block.activity_timeout_factor, 600);
  EXPECT_EQ(v.block.station_name, "drivegate");
  EXPECT_EQ(static_cast<const void*>(v.block.station_name.data()), static_cast<const void*>(kArReq.data() + 58));
}

TEST(PnBlocks, ArBlockReqMalformed) {
  // Every cut and a lying StationNameLength.
  for (std::size_t n = 0; n < kArReq.size(); ++n) EXPECT_NE(decode_ar_block_req(std::span(kArReq).first(n)).error, WireError::None);
  Bytes b = kArReq;
  b[57] = 10;  // StationNameLength 10, 9 bytes left in the block
  EXPECT_EQ(decode_ar_block_req(b).error, WireError::CountBeyondData);
  b[57] = 8;  // one byte left over
  EXPECT_EQ(decode_ar_block_req(b).error, WireError::BlockLengthMismatch);
  b = kArReq;
  b[3] = 0x30;  // BlockLength below the fixed part
  EXPECT_EQ(decode_ar_block_req(b).error, WireError::BlockLengthTooShort);
  b = kArReq;
  b[0] = 0x81;
  EXPECT_EQ(decode_ar_block_req(b).error, WireError::WrongBlockType);
  // The encoder refuses an empty or too long name and a short buffer.
  ArBlockReq a = test::Scenario{}.connect().ar;
  std::array<std::uint8_t, 512> buf{};
  a.station_name = "";
  EXPECT_EQ(encode_ar_block_req(a, buf), 0U);
  const std::string long_name(241, 'x');
  a.station_name = long_name;
  EXPECT_EQ(encode_ar_block_req(a, buf), 0U);
  a.station_name = "drivegate";
  EXPECT_EQ(encode_ar_block_req(a, std::span(buf).first(kArReq.size() - 1)), 0U);
}

TEST(PnBlocks, ArBlockRes) {
  const ArBlockRes r{ar_type::kIocarSingle, test::kArUuid, 1, test::kDeviceMac, 0x8892};
  EXPECT_EQ(encoded([&](auto o) { return encode_ar_block_res(r, o); }), kArRes);
  const ArBlockResView v = decode_ar_block_res(kArRes);
  ASSERT_EQ(v.error, WireError::None);
  EXPECT_EQ(v.block, r);
  malformed_fixed(kArRes, [](auto in) { return decode_ar_block_res(in); });
}

TEST(PnBlocks, IocrBlockReq) {
  const test::Scenario s;
  const ConnectRequest c = s.connect();
  EXPECT_EQ(encoded([&](auto o) { return encode_iocr_block_req(c.input, c.input_apis, o); }), kIocrReq);
  const IocrBlockReqView v = decode_iocr_block_req(kIocrReq);
  ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
  EXPECT_EQ(v.params, c.input);
  EXPECT_EQ(v.api_count, 2);
  IocrEntryReader r(v);
  IocrEntry e;
  std::vector<IocrEntry> all;
  while (r.next(e)) all.push_back(e);
  ASSERT_EQ(all.size(), 3U);
  EXPECT_EQ(all[0].api, 0U);
  EXPECT_FALSE(all[0].iocs);
  EXPECT_EQ(all[0].ref, (IoObjectRef{0, 1, 0}));
  EXPECT_EQ(all[1].api, 0x3A00U);
  EXPECT_FALSE(all[1].iocs);
  EXPECT_EQ(all[1].ref, (IoObjectRef{1, 1, 1}));
  EXPECT_TRUE(all[2].iocs);
  EXPECT_EQ(all[2].ref, (IoObjectRef{1, 1, 6}));
}

TEST(PnBlocks, IocrBlockReqMalformed) {
  for (std::size_t n = 0; n < kIocrReq.size(); ++n) {
    EXPECT_NE(decode_iocr_block_req(std::span(kIocrReq).first(n)).error, WireError::None) << n;
  }
  Bytes b = kIocrReq;
  b[45] = 3;  // NumberOfAPIs 3, two present
  EXPECT_EQ(decode_iocr_block_req(b).error, WireError::CountBeyondData);
  b = kIocrReq;
  b[51] = 2;  // API 0: NumberOfIODataObjects 2, one present (the rest shifts)
  EXPECT_NE(decode_iocr_block_req(b).error, WireError::None);
  b = kIocrReq;
  b[79] = 0x06;
  b[73] = 0x02;  // API 3A00h: NumberOfIOCS 2, one present
  EXPECT_EQ(decode_iocr_block_req(b).error, WireError::CountBeyondData);
  b = kIocrReq;
  b[45] = 1;  // NumberOfAPIs 1: the second API is left over
  EXPECT_EQ(decode_iocr_block_req(b).error, WireError::BlockLengthMismatch);
  b = kIocrReq;
  b[3] = 0x20;  // below the 40 fixed bytes
  EXPECT_EQ(decode_iocr_block_req(b).error, WireError::BlockLengthTooShort);
  // A reader over a failed view yields nothing.
  const IocrBlockReqView bad = decode_iocr_block_req(std::span(kIocrReq).first(50));
  IocrEntryReader r(bad);
  IocrEntry e;
  EXPECT_FALSE(r.next(e));
}

TEST(PnBlocks, IocrBlockRes) {
  const IocrBlockRes r{iocr_type::kInput, 1, 0xC001};
  EXPECT_EQ(encoded([&](auto o) { return encode_iocr_block_res(r, o); }), kIocrRes);
  const IocrBlockResView v = decode_iocr_block_res(kIocrRes);
  ASSERT_EQ(v.error, WireError::None);
  EXPECT_EQ(v.block, r);
  malformed_fixed(kIocrRes, [](auto in) { return decode_iocr_block_res(in); });
}

TEST(PnBlocks, AlarmCr) {
  const AlarmCrBlockReq req;
  EXPECT_EQ(encoded([&](auto o) { return encode_alarm_cr_block_req(req, o); }), kAlarmReq);
  const AlarmCrBlockReqView v = decode_alarm_cr_block_req(kAlarmReq);
  ASSERT_EQ(v.error, WireError::None);
  EXPECT_EQ(v.block, req);
  malformed_fixed(kAlarmReq, [](auto in) { return decode_alarm_cr_block_req(in); });

  const AlarmCrBlockRes res;
  EXPECT_EQ(encoded([&](auto o) { return encode_alarm_cr_block_res(res, o); }), kAlarmRes);
  const AlarmCrBlockResView rv = decode_alarm_cr_block_res(kAlarmRes);
  ASSERT_EQ(rv.error, WireError::None);
  EXPECT_EQ(rv.block, res);
  malformed_fixed(kAlarmRes, [](auto in) { return decode_alarm_cr_block_res(in); });
}

}  // namespace
}  // namespace drivegate::profinet
