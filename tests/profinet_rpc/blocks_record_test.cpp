// Control blocks (PrmEnd, ApplicationReady, Release and their responses), the record Read/Write
// headers and I&M0 against byte-exact vectors written from IEC 61158-6-10 §5.2.2.7 (ControlBlock),
// §5.2.2.8 (IODWriteReqHeader ... IODReadResHeader) and the I&M0 layout, and malformed input.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "adapters/profinet/wire/blocks_control.hpp"
#include "adapters/profinet/wire/blocks_record.hpp"
#include "tests/profinet_rpc/hex.hpp"
#include "tests/profinet_rpc/scenario.hpp"

namespace drivegate::profinet {
namespace {

using test::cat;
using test::hex;
using Bytes = std::vector<std::uint8_t>;

const Bytes kArUuid = hex("11 22 33 44 55 66 77 88 99 AA BB CC DD EE FF 00");

// ControlBlock: type, length 28, version 1.0, reserved, ARUUID, SessionKey, reserved,
// ControlCommand, ControlBlockProperties.
const Bytes kPrmEnd = cat({hex("01 10 | 00 1C | 01 00 | 00 00"), kArUuid, hex("00 01 | 00 00 | 00 01 | 00 00")});
const Bytes kReadyRes = cat({hex("81 12 | 00 1C | 01 00 | 00 00"), kArUuid, hex("00 01 | 00 00 | 00 08 | 00 00")});
const Bytes kRelease = cat({hex("01 14 | 00 1C | 01 00 | 00 00"), kArUuid, hex("00 01 | 00 00 | 00 04 | 00 00")});

// The digest's §5.5 request (write PNU 930 = 2) as record data of index 47 on slot 1/subslot 1.
const Bytes kPnu930 = hex("05 02 00 01 10 01 03 A2 00 00 42 01 00 02");
const Bytes kWriteReq = cat({hex("00 08 | 00 3C | 01 00 | 00 01"), kArUuid,
                             hex("00 00 3A 00 | 00 01 | 00 01 | 00 00 | 00 2F | 00 00 00 0E"), Bytes(24, 0), kPnu930});
// A refused write: PNIORW "access: access denied" in the header's PNIOStatus.
const Bytes kWriteRes = cat({hex("80 08 | 00 3C | 01 00 | 00 01"), kArUuid,
                             hex("00 00 3A 00 | 00 01 | 00 01 | 00 00 | 00 2F | 00 00 00 0E | 00 00 | 00 00 | DF 80 B6 00"),
                             Bytes(16, 0)});
const Bytes kReadReq = cat({hex("00 09 | 00 3C | 01 00 | 00 02"), kArUuid,
                            hex("00 00 00 00 | 00 00 | 00 01 | 00 00 | AF F0 | 00 00 10 00"), Bytes(24, 0)});
// I&M0: vendor 1234h, order ID and serial blank padded, HW revision 3, SW V1.18.0, revision counter
// 0, profile 3A00h (PROFIdrive), type 0, I&M version 1.1, I&M1-4 supported.
const Bytes kIm0 = cat({hex("00 20 | 00 38 | 01 00 | 12 34"), test::ascii("AKD-P00306-NBPN-0000", 20),
                        test::ascii("SN0000001", 16), hex("00 03 | 56 01 12 00 | 00 00 | 3A 00 | 00 00 | 01 01 | 00 1E")});
const Bytes kReadRes = cat({hex("80 09 | 00 3C | 01 00 | 00 02"), kArUuid,
                            hex("00 00 00 00 | 00 00 | 00 01 | 00 00 | AF F0 | 00 00 00 3C | 00 00 | 00 00"), Bytes(20, 0),
                            kIm0});

template <typename Encode>
Bytes encoded(Encode&& e) {
  std::array<std::uint8_t, 512> buf{};
  const std::size_t n = e(std::span<std::uint8_t>(buf));
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
}

RecordReqHeader write_header() {
  RecordReqHeader h;
  h.type = block_type::kWriteReqHeader;
  h.sequence_number = 1;
  h.ar_uuid = test::kArUuid;
  h.api = test::kProfidriveApi;
  h.slot = 1;
  h.subslot = 1;
  h.index = record_index::kAkdParameterAccess;
  h.record_data_length = 14;
  return h;
}

RecordReqHeader read_header() {
  RecordReqHeader h;
  h.type = block_type::kReadReqHeader;
  h.sequence_number = 2;
  h.ar_uuid = test::kArUuid;
  h.subslot = 1;
  h.index = record_index::kIm0;
  h.record_data_length = 4096;
  return h;
}

Im0 im0() {
  Im0 m;
  m.vendor_id = 0x1234;
  m.order_id = "AKD-P00306-NBPN-0000";
  m.serial_number = "SN0000001";
  m.hardware_revision = 3;
  m.software_functional = 1;
  m.software_bugfix = 0x12;
  m.profile_id = 0x3A00;
  m.im_supported = 0x001E;
  return m;
}

TEST(PnControl, Bytes) {
  const ControlBlock prm{block_type::kPrmEndReq, test::kArUuid, 1, 0, control_command::kPrmEnd, 0};
  EXPECT_EQ(encoded([&](auto o) { return encode_control_block(prm, o); }), kPrmEnd);
  const ControlBlock ready{block_type::kApplicationReadyReq, test::kArUuid, 1, 0, control_command::kApplicationReady, 0};
  EXPECT_EQ(encoded([&](auto o) { return encode_control_block(control_response_for(ready), o); }), kReadyRes);
  const ControlBlock rel{block_type::kReleaseReq, test::kArUuid, 1, 0, control_command::kRelease, 0};
  EXPECT_EQ(encoded([&](auto o) { return encode_control_block(rel, o); }), kRelease);
  for (const Bytes& b : {kPrmEnd, kReadyRes, kRelease}) {
    const ControlBlockView v = decode_control_block(b);
    ASSERT_EQ(v.error, WireError::None);
    EXPECT_EQ(v.size, kControlBlockSize);
    EXPECT_EQ(v.block.ar_uuid, test::kArUuid);
    EXPECT_EQ(v.block.session_key, 1);
  }
  EXPECT_EQ(decode_control_block(kPrmEnd).block, prm);
  EXPECT_EQ(decode_control_block(kReadyRes).block.command, control_command::kDone);
  EXPECT_EQ(decode_control_block(kReadyRes).block.type, block_type::kApplicationReadyRes);
  // Only control block types encode.
  ControlBlock wrong = prm;
  wrong.type = block_type::kArBlockReq;
  std::array<std::uint8_t, 64> buf{};
  EXPECT_EQ(encode_control_block(wrong, buf), 0U);
}

TEST(PnControl, Malformed) {
  for (std::size_t n = 0; n < kPrmEnd.size(); ++n) EXPECT_NE(decode_control_block(std::span(kPrmEnd).first(n)).error, WireError::None);
  Bytes b = kPrmEnd;
  b[1] = 0x11;  // 0111h is not a control block
  EXPECT_EQ(decode_control_block(b).error, WireError::WrongBlockType);
  b = kPrmEnd;
  b[3] = 0x1B;
  EXPECT_EQ(decode_control_block(b).error, WireError::BlockLengthTooShort);
  b = kPrmEnd;
  b[3] = 0x1D;
  b.push_back(0);
  EXPECT_EQ(decode_control_block(b).error, WireError::BlockLengthMismatch);
  b = kPrmEnd;
  b[4] = 0;
  EXPECT_EQ(decode_control_block(b).error, WireError::UnsupportedBlockVersion);
}

TEST(PnRecord, WriteBytes) {
  std::array<std::uint8_t, 128> buf{};
  const std::size_t n = encode_record_req_header(write_header(), buf);
  ASSERT_EQ(n, kRecordHeaderSize);
  EXPECT_EQ(test::bytes(std::span(buf).first(n)), Bytes(kWriteReq.begin(), kWriteReq.begin() + 64));
  const RecordReqView v = decode_record_request(kWriteReq);
  ASSERT_EQ(v.error, WireError::None) << to_string(v.error);
  EXPECT_EQ(v.header, write_header());
  EXPECT_EQ(test::bytes(v.data), kPnu930);
  EXPECT_EQ(v.data.data(), kWriteReq.data() + 64);
  EXPECT_EQ(v.size, kWriteReq.size());

  const RecordResHeader res = record_response_for(write_header(), 14, {0xDF, 0x80, 0xB6, 0x00});
  EXPECT_EQ(encoded([&](auto o) { return encode_record_res_header(res, o); }), kWriteRes);
  const RecordResView rv = decode_record_response(kWriteRes);
  ASSERT_EQ(rv.error, WireError::None);
  EXPECT_EQ(rv.header, res);
  EXPECT_FALSE(rv.header.status.ok());
  EXPECT_TRUE(rv.data.empty());
}

TEST(PnRecord, ReadBytesAndIm0) {
  EXPECT_EQ(encoded([&](auto o) { return encode_record_req_header(read_header(), o); }), kReadReq);
  const RecordReqView v = decode_record_request(kReadReq);
  ASSERT_EQ(v.error, WireError::None);
  EXPECT_EQ(v.header, read_header());
  EXPECT_TRUE(v.data.empty());  // a read request's length is the most it takes

  EXPECT_EQ(encoded([&](auto o) { return encode_im0(im0(), o); }), kIm0);
  const RecordResHeader res = record_response_for(read_header(), kIm0Size);
  Bytes head = encoded([&](auto o) { return encode_record_res_header(res, o); });
  EXPECT_EQ(head, Bytes(kReadRes.begin(), kReadRes.begin() + 64));
  const RecordResView rv = decode_record_response(kReadRes);
  ASSERT_EQ(rv.error, WireError::None) << to_string(rv.error);
  EXPECT_EQ(rv.header, res);
  ASSERT_EQ(rv.data.size(), kIm0Size);
  const Im0View m = decode_im0(rv.data);
  ASSERT_EQ(m.error, WireError::None) << to_string(m.error);
  EXPECT_EQ(m.im0, im0());
  EXPECT_EQ(m.im0.serial_number, "SN0000001");  // blanks trimmed
  EXPECT_EQ(m.im0.software_prefix, 'V');
}

TEST(PnRecord, ReadImplicitTarget) {
  RecordReqHeader h = read_header();
  h.target_ar_uuid = test::kActivity;
  std::array<std::uint8_t, 64> buf{};
  ASSERT_EQ(encode_record_req_header(h, buf), 64U);
  EXPECT_EQ(buf[40], 0x01);  // TargetARUUID in place of the first 16 padding octets
  EXPECT_EQ(decode_record_request(buf).header, h);
}

TEST(PnRecord, Malformed) {
  for (std::size_t n = 0; n < 64; ++n) EXPECT_NE(decode_record_request(std::span(kReadReq).first(n)).error, WireError::None);
  // RecordDataLength of a write beyond the data that follows.
  EXPECT_EQ(decode_record_request(std::span(kWriteReq).first(70)).error, WireError::CountBeyondData);
  EXPECT_EQ(decode_record_response(std::span(kReadRes).first(100)).error, WireError::CountBeyondData);
  Bytes b = kWriteReq;
  b[3] = 0x3B;
  EXPECT_EQ(decode_record_request(b).error, WireError::BlockLengthTooShort);
  b = kWriteReq;
  b[0] = 0x80;  // a response header is not a request
  EXPECT_EQ(decode_record_request(b).error, WireError::WrongBlockType);
  EXPECT_EQ(decode_record_response(kWriteReq).error, WireError::WrongBlockType);
  b = kWriteRes;
  b[3] = 0xFF;
  EXPECT_EQ(decode_record_response(b).error, WireError::BlockLengthBeyondData);
  // The encoders refuse the wrong kind.
  std::array<std::uint8_t, 64> buf{};
  RecordReqHeader bad = write_header();
  bad.type = block_type::kWriteResHeader;
  EXPECT_EQ(encode_record_req_header(bad, buf), 0U);
  EXPECT_EQ(encode_record_req_header(write_header(), std::span(buf).first(63)), 0U);
}

TEST(PnIm0, Malformed) {
  for (std::size_t n = 0; n < kIm0.size(); ++n) EXPECT_NE(decode_im0(std::span(kIm0).first(n)).error, WireError::None);
  Bytes b = kIm0;
  b[3] = 0x37;
  EXPECT_EQ(decode_im0(b).error, WireError::BlockLengthTooShort);
  b = kIm0;
  b[3] = 0x39;
  b.push_back(0);
  EXPECT_EQ(decode_im0(b).error, WireError::BlockLengthMismatch);
  b = kIm0;
  b[1] = 0x21;  // I&M1
  EXPECT_EQ(decode_im0(b).error, WireError::WrongBlockType);
  Im0 m = im0();
  m.order_id = "123456789012345678901";  // 21 characters
  std::array<std::uint8_t, 64> buf{};
  EXPECT_EQ(encode_im0(m, buf), 0U);
}

// I&M1: type 0021h, length 56, version 1.0, IM_Tag_Function 32 and IM_Tag_Location 22 octets,
// blank padded [IEC 61158-6-10 I&M1].
const Bytes kIm1 = cat({hex("00 21 | 00 38 | 01 00"), test::ascii("conveyor 3", 32), test::ascii("hall B", 22)});

TEST(PnIm1, BytesBothWays) {
  EXPECT_EQ(encoded([&](auto o) { return encode_im1({"conveyor 3", "hall B"}, o); }), kIm1);
  const Im1View v = decode_im1(kIm1);
  ASSERT_EQ(v.error, WireError::None);
  EXPECT_EQ(v.im1.tag_function, "conveyor 3");
  EXPECT_EQ(v.im1.tag_location, "hall B");
  EXPECT_EQ(encoded([&](auto o) { return encode_im1({}, o); }),
            cat({hex("00 21 | 00 38 | 01 00"), Bytes(54, ' ')}));
}

TEST(PnIm1, Malformed) {
  for (std::size_t n = 0; n < kIm1.size(); ++n) EXPECT_NE(decode_im1(std::span(kIm1).first(n)).error, WireError::None);
  Bytes b = kIm1;
  b.push_back(0);  // a byte after the block
  EXPECT_EQ(decode_im1(b).error, WireError::BlockLengthMismatch);
  b = kIm1;
  b[1] = 0x20;  // I&M0
  EXPECT_EQ(decode_im1(b).error, WireError::WrongBlockType);
  std::array<std::uint8_t, 64> buf{};
  EXPECT_EQ(encode_im1({std::string(33, 'x'), {}}, buf), 0U);
  EXPECT_EQ(encode_im1({{}, std::string(23, 'x')}, buf), 0U);
}

}  // namespace
}  // namespace drivegate::profinet
