// Mailbox and CoE codecs against the digest's test vectors (dunker-ethercat-coe.md §13 TV-1, TV-4,
// TV-6) and vectors derived from the CoE specification [ETG.1000.6 §5.6: CoE header, SDO
// services, emergency, SDO information] and the mailbox header [ETG.1000.6 Table 29].
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "adapters/ethercat/wire/mailbox.hpp"
#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::ethercat {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes hex(const std::string& s) {
  Bytes b;
  for (std::size_t i = 0; i + 1 < s.size(); ++i) {
    if (s[i] == ' ') continue;
    b.push_back(static_cast<std::uint8_t>(std::stoi(s.substr(i, 2), nullptr, 16)));
    ++i;
  }
  return b;
}

template <typename F>
Bytes encoded(F&& f) {
  std::array<std::uint8_t, 256> buf{};
  const std::size_t n = f(std::span<std::uint8_t>(buf));
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
}

TEST(EcatMailbox, HeaderAndCounter) {
  MailboxHeader h;
  h.length = 10;
  h.address = 0x1001;
  h.channel = 5;
  h.priority = 2;
  h.type = static_cast<std::uint8_t>(MailboxType::CoE);
  h.counter = 7;
  std::array<std::uint8_t, 6> b{};
  ASSERT_TRUE(encode_mailbox_header(h, b));
  EXPECT_EQ(Bytes(b.begin(), b.end()), hex("0A 00 01 10 85 73"));
  std::array<std::uint8_t, 16> frame{};
  std::copy(b.begin(), b.end(), frame.begin());
  const MailboxView v = decode_mailbox(frame);
  ASSERT_EQ(v.error, MailboxError::None);
  EXPECT_EQ(v.header, h);
  EXPECT_EQ(v.payload.size(), 10U);
  h.counter = 8;
  EXPECT_FALSE(encode_mailbox_header(h, b));
  // 1..7 cycling, never 0 [ETG.1000.6 mailbox header].
  EXPECT_EQ(next_mailbox_counter(0), 1);
  EXPECT_EQ(next_mailbox_counter(1), 2);
  EXPECT_EQ(next_mailbox_counter(6), 7);
  EXPECT_EQ(next_mailbox_counter(7), 1);
  EXPECT_EQ(to_string(MailboxType::VoE), "VoE");
  EXPECT_EQ(to_string(static_cast<MailboxType>(9)), "unknown");
}

// TV-6: every step of the IP-mode remap as a complete mailbox (header, CoE header 00 20 = SDO
// request, 8 SDO bytes), the counter cycling 1..7 from step 1.
TEST(EcatMailbox, DigestTv6RemapSequence) {
  struct Step {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint32_t value;
    std::size_t size;
    const char* sdo;
  };
  const std::array<Step, 16> steps{{
      {0x1C12, 0, 0, 1, "2F 12 1C 00 00 00 00 00"},
      {0x1600, 0, 0, 1, "2F 00 16 00 00 00 00 00"},
      {0x1600, 1, 0x60400010, 4, "23 00 16 01 10 00 40 60"},
      {0x1600, 2, 0x60C10120, 4, "23 00 16 02 20 01 C1 60"},
      {0x1600, 0, 2, 1, "2F 00 16 00 02 00 00 00"},
      {0x1C12, 1, 0x1600, 2, "2B 12 1C 01 00 16 00 00"},
      {0x1C12, 0, 1, 1, "2F 12 1C 00 01 00 00 00"},
      {0x1C13, 0, 0, 1, "2F 13 1C 00 00 00 00 00"},
      {0x1A00, 0, 0, 1, "2F 00 1A 00 00 00 00 00"},
      {0x1A00, 1, 0x60410010, 4, "23 00 1A 01 10 00 41 60"},
      {0x1A00, 2, 0x60630020, 4, "23 00 1A 02 20 00 63 60"},
      {0x1A00, 0, 2, 1, "2F 00 1A 00 02 00 00 00"},
      {0x1C13, 1, 0x1A00, 2, "2B 13 1C 01 00 1A 00 00"},
      {0x1C13, 0, 1, 1, "2F 13 1C 00 01 00 00 00"},
      {0x6007, 0, 1, 2, "2B 07 60 00 01 00 00 00"},
      {0x60C2, 1, 4, 1, "2F C2 60 01 04 00 00 00"},
  }};
  std::uint8_t counter = 0;
  for (const Step& s : steps) {
    counter = next_mailbox_counter(counter);
    Bytes expected = hex("0A 00 00 00 00");
    expected.push_back(static_cast<std::uint8_t>((counter << 4) | 0x03));
    const Bytes coe_sdo = hex(std::string("00 20 ") + s.sdo);
    expected.insert(expected.end(), coe_sdo.begin(), coe_sdo.end());
    EXPECT_EQ(encoded([&](auto out) { return encode_sdo_download_value(out, counter, s.index, s.sub, s.value, s.size); }),
              expected)
        << s.sdo;
    // And the server reads it back.
    const SdoView d = decode_sdo_request(expected);
    ASSERT_EQ(d.error, MailboxError::None);
    EXPECT_EQ(d.sdo.command, SdoCommand::DownloadInitiateRequest);
    EXPECT_TRUE(d.sdo.expedited);
    EXPECT_EQ(d.sdo.index, s.index);
    EXPECT_EQ(d.sdo.subindex, s.sub);
    EXPECT_EQ(d.sdo.data.size(), s.size);
    EXPECT_EQ(d.mailbox.counter, counter);
  }
  // TV-6 "Example complete frame for step 3, mailbox counter 1".
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_download_value(out, 1, 0x1600, 1, 0x60400010, 4); }),
            hex("0A 00 00 00 00 13 00 20 23 00 16 01 10 00 40 60"));
  // TV-1 entries: the u32 mapping values on the wire, little-endian.
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_download_value(out, 1, 0x1A00, 3, 0x606C0020, 4); }),
            hex("0A 00 00 00 00 13 00 20 23 00 1A 03 20 00 6C 60"));
}

// TV-6 responses: "Successful download response: 60 idx_lo idx_hi sub 00 00 00 00"; abort
// "80 idx_lo idx_hi sub <abort code u32>".
TEST(EcatMailbox, DigestTv6Responses) {
  const Bytes ok = hex("0A 00 00 00 00 23 00 30 60 00 16 01 00 00 00 00");
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_download_response(out, 2, 0x1600, 1); }), ok);
  const SdoView r = decode_sdo_response(ok);
  ASSERT_EQ(r.error, MailboxError::None);
  EXPECT_EQ(r.sdo.command, SdoCommand::DownloadInitiateResponse);
  EXPECT_EQ(r.sdo.index, 0x1600);
  EXPECT_EQ(r.sdo.subindex, 1);

  // Abort 06070010 (the retry hint of TV-6) from the server, CoE service 2.
  const Bytes abort = hex("0A 00 00 00 00 23 00 20 80 12 1C 00 10 00 07 06");
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_abort(out, 2, 0x1C12, 0, 0x06070010); }), abort);
  const SdoView a = decode_sdo_response(abort);
  ASSERT_EQ(a.error, MailboxError::None);
  EXPECT_EQ(a.sdo.command, SdoCommand::Abort);
  EXPECT_EQ(a.sdo.abort_code, 0x06070010U);
  EXPECT_EQ(cia402::sdo_abort_text(a.sdo.abort_code), "data type does not match, length of service parameter does not match");
  // Some servers send the abort as service 3; it is still an abort.
  Bytes abort3 = abort;
  abort3[7] = 0x30;
  EXPECT_EQ(decode_sdo_response(abort3).sdo.command, SdoCommand::Abort);
  EXPECT_EQ(decode_sdo_request(abort).sdo.command, SdoCommand::Abort);
}

// TV-4: emergency 8100h and A000h in SM1 (mailbox counter n, CoE service 1).
TEST(EcatMailbox, DigestTv4Emergency) {
  const Bytes comm = hex("0A 00 00 00 00 33 00 10 00 81 11 00 00 00 00 00");
  const EmergencyView e = decode_emergency(comm);
  ASSERT_EQ(e.error, MailboxError::None);
  EXPECT_EQ(e.emergency.error_code, 0x8100);
  EXPECT_EQ(e.emergency.error_register, 0x11);
  EXPECT_EQ(e.emergency.data, (std::array<std::uint8_t, 5>{}));
  EXPECT_EQ(e.mailbox.counter, 3);
  CoeEmergency esm;
  esm.error_code = 0xA000;
  esm.error_register = 0x01;
  const Bytes esm_bytes = hex("0A 00 00 00 00 13 00 10 00 A0 01 00 00 00 00 00");
  EXPECT_EQ(encoded([&](auto out) { return encode_emergency(out, 1, esm); }), esm_bytes);
  EXPECT_EQ(decode_emergency(esm_bytes).emergency, esm);
  // Vendor bytes are kept [ETG.1000.6 §5.6.4: 5 bytes of manufacturer data].
  const Bytes vendor = hex("0A 00 00 00 00 13 00 10 10 23 04 01 02 03 04 05");
  EXPECT_EQ(decode_emergency(vendor).emergency.data, (std::array<std::uint8_t, 5>{1, 2, 3, 4, 5}));
}

// Normal and segmented transfers [ETG.1000.6 §5.6.2.2-§5.6.2.6]: a 12-byte download of 1008h
// split as 3 bytes in the initiate and 9 in one segment; an upload with a 3-byte last segment.
TEST(EcatMailbox, NormalAndSegmented) {
  const Bytes text = {'d', 'r', 'i', 'v', 'e', 'g', 'a', 't', 'e', '-', 'f', '1'};
  // Initiate: mailbox length 10 + 3, command 21h (s = 1), complete size 12.
  const Bytes init = hex("0D 00 00 00 00 13 00 20 21 08 10 00 0C 00 00 00 64 72 69");
  EXPECT_EQ(encoded([&](auto out) {
              return encode_sdo_download_normal(out, 1, 0x1008, 0, 12, std::span(text).first(3));
            }),
            init);
  const SdoView di = decode_sdo_request(init);
  ASSERT_EQ(di.error, MailboxError::None);
  EXPECT_FALSE(di.sdo.expedited);
  EXPECT_TRUE(di.sdo.size_indicated);
  EXPECT_EQ(di.sdo.size, 12U);
  EXPECT_EQ(Bytes(di.sdo.data.begin(), di.sdo.data.end()), Bytes(text.begin(), text.begin() + 3));
  // Segment of 9 bytes: longer than 7, so no unused count; last; toggle 0: command 01h.
  const Bytes seg = hex("0C 00 00 00 00 23 00 20 01 76 65 67 61 74 65 2D 66 31");
  EXPECT_EQ(encoded([&](auto out) { return encode_sdo_download_segment(out, 2, false, true, std::span(text).subspan(3)); }),
            seg);
  const SdoView ds = decode_sdo_request(seg);
  ASSERT_EQ(ds.error, MailboxError::None);
  EXPECT_EQ(ds.sdo.command, SdoCommand::DownloadSegmentRequest);
  EXPECT_TRUE(ds.sdo.last);
  EXPECT_FALSE(ds.sdo.toggle);
  EXPECT_EQ(ds.sdo.data.size(), 9U);
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_download_segment_response(out, 3, true); }),
            hex("0A 00 00 00 00 33 00 30 30 00 00 00 00 00 00 00"));
  EXPECT_TRUE(decode_sdo_response(hex("0A 00 00 00 00 33 00 30 30 00 00 00 00 00 00 00")).sdo.toggle);

  // Upload: request 40h, normal response 41h with size and the first bytes, then a short
  // segment (3 bytes: unused 4 in bits 1-3, toggle 1, last): 10h | 08h | 01h = 19h.
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_upload_request(out, 4, 0x1008, 0); }),
            hex("0A 00 00 00 00 43 00 20 40 08 10 00 00 00 00 00"));
  const Bytes up = hex("0E 00 00 00 00 43 00 30 41 08 10 00 0C 00 00 00 64 72 69 76");
  EXPECT_EQ(encoded([&](auto out) { return encode_sdo_upload_normal_response(out, 4, 0x1008, 0, 12, std::span(text).first(4)); }),
            up);
  const SdoView u = decode_sdo_response(up);
  ASSERT_EQ(u.error, MailboxError::None);
  EXPECT_EQ(u.sdo.command, SdoCommand::UploadInitiateResponse);
  EXPECT_EQ(u.sdo.size, 12U);
  EXPECT_EQ(u.sdo.data.size(), 4U);
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_upload_segment_request(out, 5, true); }),
            hex("0A 00 00 00 00 53 00 20 70 00 00 00 00 00 00 00"));
  const Bytes last = hex("0A 00 00 00 00 53 00 30 19 2D 66 31 00 00 00 00");
  EXPECT_EQ(encoded([&](auto out) { return encode_sdo_upload_segment_response(out, 5, true, true, std::span(text).subspan(9)); }),
            last);
  const SdoView us = decode_sdo_response(last);
  ASSERT_EQ(us.error, MailboxError::None);
  EXPECT_EQ(us.sdo.command, SdoCommand::UploadSegmentResponse);
  EXPECT_TRUE(us.sdo.toggle);
  EXPECT_TRUE(us.sdo.last);
  EXPECT_EQ(Bytes(us.sdo.data.begin(), us.sdo.data.end()), Bytes(text.begin() + 9, text.end()));
  EXPECT_EQ(decode_sdo_request(hex("0A 00 00 00 00 53 00 20 70 00 00 00 00 00 00 00")).sdo.command,
            SdoCommand::UploadSegmentRequest);
}

// Expedited upload response 4Bh (2 bytes) and complete access flags (bit 4).
TEST(EcatMailbox, ExpeditedUploadAndCompleteAccess) {
  const std::array<std::uint8_t, 2> val{0x00, 0x16};
  const Bytes resp = hex("0A 00 00 00 00 13 00 30 4B 12 1C 01 00 16 00 00");
  EXPECT_EQ(encoded([&](auto out) { return encode_sdo_upload_expedited_response(out, 1, 0x1C12, 1, val); }), resp);
  const SdoView r = decode_sdo_response(resp);
  ASSERT_EQ(r.error, MailboxError::None);
  EXPECT_TRUE(r.sdo.expedited);
  EXPECT_EQ(r.sdo.size, 2U);
  EXPECT_EQ(Bytes(r.sdo.data.begin(), r.sdo.data.end()), Bytes(val.begin(), val.end()));
  // Expedited without size indication (42h): 4 data bytes.
  EXPECT_EQ(decode_sdo_response(hex("0A 00 00 00 00 13 00 30 42 00 10 00 92 01 02 00")).sdo.data.size(), 4U);
  // Complete access upload of 1C12h from subindex 0: 50h.
  const Bytes ca = hex("0A 00 00 00 00 13 00 20 50 12 1C 00 00 00 00 00");
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_upload_request(out, 1, 0x1C12, 0, true); }), ca);
  EXPECT_TRUE(decode_sdo_request(ca).sdo.complete_access);
  // Complete access download of 1C12h: 31h.
  const std::array<std::uint8_t, 4> all{0x01, 0x00, 0x00, 0x16};
  const Bytes cad = hex("0E 00 00 00 00 13 00 20 31 12 1C 00 04 00 00 00 01 00 00 16");
  EXPECT_EQ(encoded([&](auto out) { return encode_sdo_download_normal(out, 1, 0x1C12, 0, 4, all, true); }), cad);
  EXPECT_TRUE(decode_sdo_request(cad).sdo.complete_access);
}

// Abort texts come from the one table CANopen also uses; CoE adds 0601000[3-6]h [ETG.1000.6
// §5.6.2.7.2].
TEST(EcatMailbox, AbortTexts) {
  EXPECT_EQ(cia402::sdo_abort_text(0x06020000), "object does not exist in the object dictionary");
  EXPECT_EQ(cia402::sdo_abort_text(0x06010004), "complete access not supported for objects of variable length");
  EXPECT_EQ(cia402::sdo_abort_text(0x06010006), "object mapped to an RxPDO, SDO download blocked");
  EXPECT_EQ(cia402::sdo_abort_text(0x12345678), "unknown abort code");
}

TEST(EcatMailbox, EncodersRefuseBadArguments) {
  std::array<std::uint8_t, 15> small{};
  EXPECT_EQ(encode_sdo_upload_request(small, 1, 0x1000, 0), 0U);  // needs 16
  std::array<std::uint8_t, 64> buf{};
  EXPECT_EQ(encode_sdo_download_value(buf, 1, 0x1000, 0, 0, 0), 0U);
  EXPECT_EQ(encode_sdo_download_value(buf, 1, 0x1000, 0, 0, 5), 0U);
  EXPECT_EQ(encode_sdo_download_value(buf, 8, 0x1000, 0, 0, 1), 0U);  // counter beyond 3 bits
  const std::array<std::uint8_t, 5> five{};
  EXPECT_EQ(encode_sdo_download_expedited(buf, 1, 0x1000, 0, five), 0U);
  EXPECT_EQ(encode_sdo_download_normal(buf, 1, 0x1000, 0, 4, five), 0U);  // more data than size
  EXPECT_EQ(encode_sdo_upload_expedited_response(buf, 1, 0x1000, 0, {}), 0U);
}

// Malformed mailboxes: a clear error each, never a read past the bytes given.
TEST(EcatMailbox, MalformedInput) {
  EXPECT_EQ(decode_mailbox(hex("0A 00 00 00 00")).error, MailboxError::TruncatedHeader);
  EXPECT_EQ(decode_mailbox(hex("0B 00 00 00 00 13 00 20 40 00 10 00 00 00 00 00")).error,
            MailboxError::LengthBeyondBuffer);
  // A whole SM1 buffer: bytes after `length` are ignored.
  const Bytes padded = hex("0A 00 00 00 00 13 00 30 60 00 16 01 00 00 00 00 FF FF FF FF");
  EXPECT_EQ(decode_sdo_response(padded).error, MailboxError::None);
  EXPECT_EQ(decode_coe(hex("0A 00 00 00 00 14 00 20 40 00 10 00 00 00 00 00")).error, MailboxError::WrongType);
  EXPECT_EQ(decode_coe(hex("01 00 00 00 00 13 00")).error, MailboxError::TruncatedCoeHeader);
  EXPECT_EQ(decode_sdo_request(hex("09 00 00 00 00 13 00 20 40 00 10 00 00 00 00")).error, MailboxError::TruncatedSdo);
  EXPECT_EQ(decode_sdo_request(hex("0A 00 00 00 00 13 00 80 40 00 10 00 00 00 00 00")).error,
            MailboxError::UnexpectedService);
  // A response where a request is expected, and the other way round.
  EXPECT_EQ(decode_sdo_request(hex("0A 00 00 00 00 13 00 30 60 00 10 00 00 00 00 00")).error,
            MailboxError::UnexpectedService);
  EXPECT_EQ(decode_sdo_response(hex("0A 00 00 00 00 13 00 20 40 00 10 00 00 00 00 00")).error,
            MailboxError::UnexpectedService);
  for (const char* cs : {"A0", "C0", "E0"}) {  // cs 5, 6 (block), 7
    EXPECT_EQ(decode_sdo_request(hex(std::string("0A 00 00 00 00 13 00 20 ") + cs + " 00 10 00 00 00 00 00")).error,
              MailboxError::UnknownSdoCommand);
    EXPECT_EQ(decode_sdo_response(hex(std::string("0A 00 00 00 00 13 00 30 ") + cs + " 00 10 00 00 00 00 00")).error,
              MailboxError::UnknownSdoCommand);
  }
  // Normal initiate carrying more data than its complete size.
  EXPECT_EQ(decode_sdo_request(hex("0D 00 00 00 00 13 00 20 21 08 10 00 02 00 00 00 64 72 69")).error,
            MailboxError::SizeMismatch);
  EXPECT_EQ(decode_emergency(hex("09 00 00 00 00 13 00 10 00 81 00 00 00 00 00")).error,
            MailboxError::TruncatedEmergency);
  EXPECT_EQ(decode_emergency(hex("0A 00 00 00 00 13 00 20 40 00 10 00 00 00 00 00")).error,
            MailboxError::UnexpectedService);
  for (int i = 0; i <= static_cast<int>(MailboxError::TruncatedMailboxError); ++i) {
    EXPECT_NE(to_string(static_cast<MailboxError>(i)), "?");
  }
}

// Mailbox error reply (type 0): type 0001h, detail [ETG.1000.6 mailbox error reply].
TEST(EcatMailbox, ErrorReply) {
  const Bytes reply = hex("04 00 00 00 00 10 01 00 02 00");
  EXPECT_EQ(encoded([](auto out) { return encode_mailbox_error(out, 1, mailbox_error_code::kUnsupportedProtocol); }),
            reply);
  const MailboxErrorReply r = decode_mailbox_error(reply);
  ASSERT_EQ(r.error, MailboxError::None);
  EXPECT_EQ(r.type, 1);
  EXPECT_EQ(r.detail, 2);
  EXPECT_EQ(mailbox_error_text(r.detail), "mailbox protocol not supported");
  EXPECT_EQ(mailbox_error_text(0x0008), "length of the data is inconsistent");
  EXPECT_EQ(mailbox_error_text(0x1234), "unknown mailbox error");
  EXPECT_EQ(decode_mailbox_error(hex("02 00 00 00 00 10 01 00")).error, MailboxError::TruncatedMailboxError);
  EXPECT_EQ(decode_mailbox_error(hex("04 00 00 00 00 13 01 00 02 00")).error, MailboxError::WrongType);
  EXPECT_EQ(decode_mailbox_error(hex("04 00 00 00 00")).error, MailboxError::TruncatedHeader);
}

// SDO information [ETG.1000.6 §5.6.3]: CoE service 8 (header 00 80), then opcode, reserved,
// fragments left, data.
TEST(EcatMailbox, SdoInfoOdList) {
  const Bytes req = hex("08 00 00 00 00 13 00 80 01 00 00 00 01 00");
  EXPECT_EQ(encoded([](auto out) { return encode_get_od_list_request(out, 1, OdListType::All); }), req);
  const SdoInfoView rq = decode_sdo_info(req);
  ASSERT_EQ(rq.error, MailboxError::None);
  EXPECT_EQ(rq.opcode, SdoInfoOpcode::GetOdListRequest);
  EXPECT_EQ(rq.list_type, 1);

  // First fragment: incomplete bit, 1 fragment left, list type 1, then 1000h 1018h 6040h.
  const std::array<std::uint16_t, 3> first{0x1000, 0x1018, 0x6040};
  const Bytes f1 = hex("0E 00 00 00 00 23 00 80 82 00 01 00 01 00 00 10 18 10 40 60");
  EXPECT_EQ(encoded([&](auto out) { return encode_get_od_list_response(out, 2, OdListType::All, true, 1, first); }), f1);
  const SdoInfoView r1 = decode_sdo_info(f1, true);
  ASSERT_EQ(r1.error, MailboxError::None);
  EXPECT_EQ(r1.opcode, SdoInfoOpcode::GetOdListResponse);
  EXPECT_TRUE(r1.incomplete);
  EXPECT_EQ(r1.fragments_left, 1);
  EXPECT_TRUE(r1.has_list_type);
  ASSERT_EQ(r1.index_count(), 3U);
  EXPECT_EQ(r1.index_at(2), 0x6040);
  // Last fragment: indexes only.
  const std::array<std::uint16_t, 1> rest{0x6041};
  const Bytes f2 = hex("08 00 00 00 00 33 00 80 02 00 00 00 41 60");
  EXPECT_EQ(encoded([&](auto out) { return encode_get_od_list_response(out, 3, OdListType::All, false, 0, rest); }), f2);
  const SdoInfoView r2 = decode_sdo_info(f2, false);
  ASSERT_EQ(r2.error, MailboxError::None);
  EXPECT_FALSE(r2.incomplete);
  EXPECT_FALSE(r2.has_list_type);
  ASSERT_EQ(r2.index_count(), 1U);
  EXPECT_EQ(r2.index_at(0), 0x6041);
}

TEST(EcatMailbox, SdoInfoDescriptions) {
  EXPECT_EQ(encoded([](auto out) { return encode_get_object_description_request(out, 1, 0x6040); }),
            hex("08 00 00 00 00 13 00 80 03 00 00 00 40 60"));
  // Object 6040h: UNSIGNED16 (0006h), max subindex 0, VAR (7), "Controlword".
  SdoInfoObjectDescription od;
  od.index = 0x6040;
  od.data_type = 0x0006;
  od.max_subindex = 0;
  od.object_code = object_code::kVariable;
  od.name = "Controlword";
  const Bytes odr = hex("17 00 00 00 00 23 00 80 04 00 00 00 40 60 06 00 00 07 43 6F 6E 74 72 6F 6C 77 6F 72 64");
  EXPECT_EQ(encoded([&](auto out) { return encode_get_object_description_response(out, 2, od); }), odr);
  const SdoInfoView o = decode_sdo_info(odr);
  ASSERT_EQ(o.error, MailboxError::None);
  EXPECT_EQ(o.object.index, 0x6040);
  EXPECT_EQ(o.object.data_type, 6);
  EXPECT_EQ(o.object.object_code, 7);
  EXPECT_EQ(o.object.name, "Controlword");

  // Entry 6060h:00, asking for default/min/max (70h).
  const Bytes eq = hex("0A 00 00 00 00 13 00 80 05 00 00 00 60 60 00 70");
  EXPECT_EQ(encoded([](auto out) { return encode_get_entry_description_request(out, 1, 0x6060, 0, 0x70); }), eq);
  EXPECT_EQ(decode_sdo_info(eq).entry.value_info, 0x70);
  // Response: INTEGER16 (0003h), 16 bits, access RW in all states + RxPDO mappable (007Fh),
  // default 0, min -5, max 10, name "Modes". The ESR quirk: 6060h is 16-bit (digest quirk 1).
  SdoInfoEntryDescription ed;
  ed.index = 0x6060;
  ed.subindex = 0;
  ed.value_info = value_info::kDefault | value_info::kMinimum | value_info::kMaximum;
  ed.data_type = 0x0003;
  ed.bit_length = 16;
  ed.object_access = 0x007F;
  const std::array<std::uint8_t, 2> def{0x00, 0x00}, mn{0xFB, 0xFF}, mx{0x0A, 0x00};
  ed.default_value = def;
  ed.minimum = mn;
  ed.maximum = mx;
  ed.name = "Modes";
  const Bytes er = hex("1B 00 00 00 00 23 00 80 06 00 00 00 60 60 00 70 03 00 10 00 7F 00 00 00 FB FF 0A 00 4D 6F 64 65 73");
  EXPECT_EQ(encoded([&](auto out) { return encode_get_entry_description_response(out, 2, ed); }), er);
  const SdoInfoView e = decode_sdo_info(er);
  ASSERT_EQ(e.error, MailboxError::None);
  EXPECT_EQ(e.entry.bit_length, 16);
  EXPECT_EQ(e.entry.object_access & object_access::kRxPdoMappable, object_access::kRxPdoMappable);
  EXPECT_EQ(Bytes(e.entry.minimum.begin(), e.entry.minimum.end()), Bytes(mn.begin(), mn.end()));
  EXPECT_EQ(e.entry.name, "Modes");
  // Unit type present (bit 3).
  SdoInfoEntryDescription unit = ed;
  unit.value_info = value_info::kUnitType;
  unit.unit_type = 0x00FD0000;
  const Bytes ur = encoded([&](auto out) { return encode_get_entry_description_response(out, 2, unit); });
  const SdoInfoView u = decode_sdo_info(ur);
  ASSERT_EQ(u.error, MailboxError::None);
  EXPECT_EQ(u.entry.unit_type, 0x00FD0000U);
  EXPECT_TRUE(u.entry.default_value.empty());
  EXPECT_EQ(u.entry.name, "Modes");
  // Value lengths must match the bit length.
  SdoInfoEntryDescription bad = ed;
  bad.bit_length = 32;
  EXPECT_EQ(encoded([&](auto out) { return encode_get_entry_description_response(out, 2, bad); }).size(), 0U);

  // SDO info error with abort code 06020000.
  const Bytes err = hex("0A 00 00 00 00 13 00 80 07 00 00 00 00 00 02 06");
  EXPECT_EQ(encoded([](auto out) { return encode_sdo_info_error(out, 1, 0x06020000); }), err);
  const SdoInfoView x = decode_sdo_info(err);
  ASSERT_EQ(x.error, MailboxError::None);
  EXPECT_EQ(x.opcode, SdoInfoOpcode::Error);
  EXPECT_EQ(cia402::sdo_abort_text(x.abort_code), "object does not exist in the object dictionary");
}

TEST(EcatMailbox, SdoInfoMalformed) {
  EXPECT_EQ(decode_sdo_info(hex("05 00 00 00 00 13 00 80 01 00 00")).error, MailboxError::TruncatedSdoInfo);
  EXPECT_EQ(decode_sdo_info(hex("06 00 00 00 00 13 00 80 08 00 00 00")).error, MailboxError::UnknownSdoInfoOpcode);
  EXPECT_EQ(decode_sdo_info(hex("06 00 00 00 00 13 00 80 00 00 00 00")).error, MailboxError::UnknownSdoInfoOpcode);
  EXPECT_EQ(decode_sdo_info(hex("06 00 00 00 00 13 00 20 01 00 00 00")).error, MailboxError::UnexpectedService);
  EXPECT_EQ(decode_sdo_info(hex("06 00 00 00 00 13 00 80 01 00 00 00")).error, MailboxError::TruncatedSdoInfo);
  EXPECT_EQ(decode_sdo_info(hex("06 00 00 00 00 13 00 80 02 00 00 00")).error, MailboxError::TruncatedSdoInfo);
  EXPECT_EQ(decode_sdo_info(hex("09 00 00 00 00 13 00 80 04 00 00 00 40 60 06")).error, MailboxError::TruncatedSdoInfo);
  EXPECT_EQ(decode_sdo_info(hex("07 00 00 00 00 13 00 80 05 00 00 00 40")).error, MailboxError::TruncatedSdoInfo);
  // Entry description flagging a maximum it does not carry.
  EXPECT_EQ(decode_sdo_info(hex("11 00 00 00 00 13 00 80 06 00 00 00 60 60 00 40 03 00 10 00 7F 00 0A")).error,
            MailboxError::TruncatedSdoInfo);
  EXPECT_EQ(decode_sdo_info(hex("10 00 00 00 00 13 00 80 06 00 00 00 60 60 00 08 03 00 10 00 7F 00")).error,
            MailboxError::TruncatedSdoInfo);  // unit type flagged, absent
  EXPECT_EQ(decode_sdo_info(hex("07 00 00 00 00 13 00 80 07 00 00 00 00")).error, MailboxError::TruncatedSdoInfo);
  // An odd trailing byte in an OD list is not an index.
  EXPECT_EQ(decode_sdo_info(hex("09 00 00 00 00 13 00 80 02 00 00 00 01 00 00")).index_count(), 0U);
}

}  // namespace
}  // namespace drivegate::ethercat
