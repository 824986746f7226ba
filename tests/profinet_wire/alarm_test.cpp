// Alarms over RTA [IEC 61158-6-10: the RTA-PDU header (AlarmDstEndpoint, AlarmSrcEndpoint,
// PDUType, AddFlags, SendSeqNum, AckSeqNum, VarPartLen), the AlarmNotification-PDU and the
// AlarmAck-PDU with their BlockHeader]: a diagnosis alarm from the device, the controller's RTA
// ACK, its AlarmAck as DATA, an ERR, byte for byte; and malformed input for every decoder. Ident
// numbers are illustrative; API 3A00h is the PROFIdrive API (akd-profinet-profidrive.md §2).
#include "adapters/profinet/wire/alarm.hpp"

#include <gtest/gtest.h>

#include <array>

#include "adapters/profinet/wire/ethernet.hpp"
#include "tests/profinet_wire/bytes.hpp"

namespace drivegate::profinet {
namespace {

using test::Bytes;
using test::hex;

// ChannelDiagnosis item: ChannelNumber 8000h (the whole submodule), ChannelProperties 0800h
// (specifier "appears"), ChannelErrorType 0001h (short circuit).
constexpr std::array<std::uint8_t, 6> kChannelDiag{0x80, 0x00, 0x08, 0x00, 0x00, 0x01};

AlarmNotification diagnosis_alarm() {
  AlarmNotification n;
  n.priority = AlarmPriority::High;
  n.alarm_type = alarm_type::kDiagnosis;
  n.api = 0x3A00;
  n.slot = 1;
  n.subslot = 1;
  n.module_ident = 0x00000010;
  n.submodule_ident = 0x00000001;
  n.specifier.sequence = 5;
  n.specifier.channel_diagnosis = true;
  n.specifier.submodule_diagnosis = true;
  n.specifier.ar_diagnosis = true;
  n.has_user_structure = true;
  n.user_structure_id = user_structure::kChannelDiagnosis;
  n.user_data = kChannelDiag;
  return n;
}

// Device -> controller: DATA, TACK, first SendSeqNum 0, AckSeqNum FFFFh (nothing received yet).
const Bytes kAlarmData = hex(
    "00 01 00 03 11 11 00 00 FF FF 00 22"    // RTA header, VarPartLen 34
    "00 01 00 1E 01 00"                      // AlarmNotification high, BlockLength 30, version 1.0
    "00 01 00 00 3A 00 00 01 00 01"          // Diagnosis, API 3A00h, slot 1, subslot 1
    "00 00 00 10 00 00 00 01"                // module / submodule ident
    "A8 05"                                  // AlarmSpecifier: seq 5, channel, submodule and AR diagnosis
    "80 00 80 00 08 00 00 01");              // USI ChannelDiagnosis + one channel
// Controller -> device: the RTA acknowledgement of SendSeqNum 0.
const Bytes kRtaAck = hex("00 03 00 01 13 01 FF FF 00 00 00 00");
// Controller -> device: AlarmAck high as DATA, SendSeqNum 0, AckSeqNum 0.
const Bytes kAckData = hex(
    "00 03 00 01 11 11 00 00 00 00 00 16"
    "80 01 00 12 01 00 00 01 00 00 3A 00 00 01 00 01 A8 05 00 00 00 00");

TEST(PnAlarm, NotificationDataBytes) {
  std::array<std::uint8_t, 1500> buf{};
  const std::size_t block = encode_alarm_notification(std::span(buf).subspan(kRtaHeaderSize), diagnosis_alarm());
  ASSERT_EQ(block, 34U);
  RtaHeader h;
  h.dst_endpoint = 0x0001;
  h.src_endpoint = 0x0003;
  h.type = RtaPduType::Data;
  h.tack = true;
  h.send_seq = next_rta_seq(kRtaInitialSendSeq);
  h.ack_seq = next_rta_seq(kRtaInitialAckSeq);
  // The block already sits behind the header: encode_rta moves nothing.
  const std::size_t n = encode_rta(buf, h, std::span(buf).subspan(kRtaHeaderSize, block));
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)), kAlarmData);
}

TEST(PnAlarm, NotificationDecodes) {
  const RtaView r = decode_rta(kAlarmData);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_EQ(r.header.type, RtaPduType::Data);
  EXPECT_EQ(r.header.version, 1);
  EXPECT_EQ(r.header.window_size, 1);
  EXPECT_TRUE(r.header.tack);
  EXPECT_EQ(r.header.send_seq, 0);
  EXPECT_EQ(r.header.ack_seq, 0xFFFF);
  EXPECT_EQ(r.header.var_part_len, 34);
  EXPECT_EQ(alarm_block_type(r.var_part), alarm_block::kNotificationHigh);
  const AlarmNotificationView v = decode_alarm_notification(r.var_part);
  ASSERT_TRUE(v.ok()) << to_string(v.error);
  const AlarmNotification& n = v.notification;
  const AlarmNotification want = diagnosis_alarm();
  EXPECT_EQ(n.priority, AlarmPriority::High);
  EXPECT_EQ(n.alarm_type, want.alarm_type);
  EXPECT_EQ(n.api, want.api);
  EXPECT_EQ(n.slot, 1);
  EXPECT_EQ(n.subslot, 1);
  EXPECT_EQ(n.module_ident, want.module_ident);
  EXPECT_EQ(n.submodule_ident, want.submodule_ident);
  EXPECT_EQ(n.specifier, want.specifier);
  EXPECT_TRUE(n.has_user_structure);
  EXPECT_EQ(n.user_structure_id, user_structure::kChannelDiagnosis);
  EXPECT_EQ(Bytes(n.user_data.begin(), n.user_data.end()), Bytes(kChannelDiag.begin(), kChannelDiag.end()));
  EXPECT_EQ(n.user_data.data(), kAlarmData.data() + 28 + 12);
}

TEST(PnAlarm, NotificationWithoutItemAndLow) {
  AlarmNotification n;
  n.priority = AlarmPriority::Low;
  n.alarm_type = alarm_type::kPull;
  n.slot = 2;
  n.subslot = 0x8001;
  std::array<std::uint8_t, 64> buf{};
  const std::size_t len = encode_alarm_notification(buf, n);
  ASSERT_EQ(len, 26U);
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + 26),
            hex("00 02 00 16 01 00 00 03 00 00 00 00 00 02 80 01 00 00 00 00 00 00 00 00 00 00"));
  const AlarmNotificationView v = decode_alarm_notification(std::span(buf).first(len));
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.notification.priority, AlarmPriority::Low);
  EXPECT_FALSE(v.notification.has_user_structure);
  EXPECT_EQ(alarm_type_name(v.notification.alarm_type), "Pull");
}

TEST(PnAlarm, RtaAckBytes) {
  std::array<std::uint8_t, 64> buf{};
  RtaHeader h;
  h.dst_endpoint = 0x0003;
  h.src_endpoint = 0x0001;
  h.type = RtaPduType::Ack;
  h.send_seq = kRtaInitialSendSeq;
  h.ack_seq = 0;
  const std::size_t n = encode_rta(buf, h, {});
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)), kRtaAck);
  const RtaView r = decode_rta(kRtaAck);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.header.type, RtaPduType::Ack);
  EXPECT_FALSE(r.header.tack);
  EXPECT_EQ(r.header.ack_seq, 0);
  EXPECT_TRUE(r.var_part.empty());
}

TEST(PnAlarm, AlarmAckBytesAndDecode) {
  const AlarmNotification n = diagnosis_alarm();
  std::array<std::uint8_t, 64> block{};
  const std::size_t len = encode_alarm_ack(block, ack_for(n));
  ASSERT_EQ(len, kAlarmAckSize);
  std::array<std::uint8_t, 64> buf{};
  RtaHeader h;
  h.dst_endpoint = 0x0003;
  h.src_endpoint = 0x0001;
  h.tack = true;
  h.send_seq = 0;
  h.ack_seq = 0;
  const std::size_t total = encode_rta(buf, h, std::span(block).first(len));
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(total)), kAckData);
  const RtaView r = decode_rta(kAckData);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(alarm_block_type(r.var_part), alarm_block::kAckHigh);
  const AlarmAckView a = decode_alarm_ack(r.var_part);
  ASSERT_TRUE(a.ok()) << to_string(a.error);
  EXPECT_EQ(a.ack, ack_for(n));
  EXPECT_TRUE(a.ack.status.ok());
}

TEST(PnAlarm, ErrBytes) {
  std::array<std::uint8_t, 64> buf{};
  RtaHeader h;
  h.dst_endpoint = 0x0003;
  h.src_endpoint = 0x0001;
  h.send_seq = 0xFFFF;
  h.ack_seq = 0xFFFE;
  // ErrorCode CFh (RTA error), ErrorDecode 81h (PNIO), ErrorCode1 FDh (RTA_ERR_CLS_PROTOCOL),
  // ErrorCode2 06h (tshark: "AR cmi timeout").
  const std::size_t n = encode_rta_error(buf, h, RtaPnioStatus{0xCF, 0x81, 0xFD, 0x06});
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)),
            hex("00 03 00 01 14 01 FF FF FF FE 00 04 CF 81 FD 06"));
  const RtaView r = decode_rta(std::span(buf).first(n));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.header.type, RtaPduType::Err);
  EXPECT_EQ(rta_error_status(r), (RtaPnioStatus{0xCF, 0x81, 0xFD, 0x06}));
}

TEST(PnAlarm, ChannelDiagnosisItems) {
  const AlarmNotificationView v = decode_alarm_notification(std::span(kAlarmData).subspan(12));
  ASSERT_TRUE(v.ok());
  const ChannelDiagnosisList l = decode_channel_diagnosis(v.notification.user_structure_id, v.notification.user_data);
  ASSERT_EQ(l.error, AlarmError::None);
  ASSERT_EQ(l.count(), 1U);
  ChannelDiagnosis c;
  ASSERT_TRUE(l.get(0, c));
  EXPECT_EQ(c.channel, kChannelWholeSubmodule);
  EXPECT_TRUE(c.appears());
  EXPECT_EQ(c.maintenance(), 0);
  EXPECT_EQ(c.direction(), 0);
  EXPECT_FALSE(c.accumulative());
  EXPECT_EQ(channel_error_type_name(c.error_type), "short circuit");
  EXPECT_FALSE(l.get(1, c));
  // ExtChannelDiagnosis: two entries of 12 octets; channel 3, direction output, disappears, accumulative.
  const Bytes ext = hex("0003 5101 0006 8000 00000001  8000 0800 0011 0000 00000000");
  const ChannelDiagnosisList e = decode_channel_diagnosis(user_structure::kExtChannelDiagnosis, ext);
  ASSERT_EQ(e.count(), 2U);
  ASSERT_TRUE(e.get(0, c));
  EXPECT_EQ(c.channel, 3);
  EXPECT_EQ(c.direction(), 2);
  EXPECT_EQ(c.specifier(), 2);
  EXPECT_TRUE(c.accumulative());
  EXPECT_EQ(c.error_type, 6);
  EXPECT_EQ(c.ext_error_type, 0x8000);
  EXPECT_EQ(c.ext_add_value, 1U);
  ASSERT_TRUE(e.get(1, c));
  EXPECT_EQ(channel_error_type_name(c.error_type), "power supply fault");
  const Bytes q = hex("0001 0800 0002 0000 00000000 00000008");
  ASSERT_TRUE(decode_channel_diagnosis(user_structure::kQualifiedChannelDiagnosis, q).get(0, c));
  EXPECT_EQ(c.qualifier, 8U);
  // Malformed: another USI, a partial entry, none at all.
  EXPECT_EQ(decode_channel_diagnosis(user_structure::kMaintenance, ext).error, AlarmError::NotChannelDiagnosis);
  EXPECT_EQ(decode_channel_diagnosis(user_structure::kExtChannelDiagnosis, std::span(ext).first(13)).error,
            AlarmError::ChannelDiagnosisLength);
  EXPECT_EQ(decode_channel_diagnosis(user_structure::kChannelDiagnosis, {}).error, AlarmError::ChannelDiagnosisLength);
  EXPECT_EQ(decode_channel_diagnosis(user_structure::kChannelDiagnosis, {}).count(), 0U);
  EXPECT_EQ(channel_error_type_name(0x0013), "reserved");
  EXPECT_EQ(channel_error_type_name(0x0100), "manufacturer specific");
  EXPECT_EQ(channel_error_type_name(0x8006), "reserved");
}

TEST(PnAlarm, Sequences) {
  EXPECT_EQ(next_rta_seq(kRtaInitialSendSeq), 0);
  EXPECT_EQ(next_rta_seq(kRtaInitialAckSeq), 0xFFFF);
  EXPECT_EQ(next_rta_seq(0), 1);
  EXPECT_EQ(next_rta_seq(0x7FFF), 0);
  EXPECT_EQ(next_alarm_sequence(0x07FF), 0);
  EXPECT_EQ(next_alarm_sequence(5), 6);
  AlarmSpecifier s;
  s.sequence = 0x0FFF;  // masked to 11 bits
  s.manufacturer_diagnosis = true;
  EXPECT_EQ(encode_alarm_specifier(s), 0x17FF);
  EXPECT_EQ(decode_alarm_specifier(0xA805), diagnosis_alarm().specifier);
}

TEST(PnAlarm, Names) {
  EXPECT_EQ(alarm_type_name(alarm_type::kDiagnosis), "Diagnosis");
  EXPECT_EQ(alarm_type_name(alarm_type::kReturnOfSubmodule), "Return of submodule");
  EXPECT_EQ(alarm_type_name(alarm_type::kPlug), "Plug");
  EXPECT_EQ(alarm_type_name(alarm_type::kPullModule), "Pull module");
  EXPECT_EQ(alarm_type_name(0x0040), "manufacturer specific");
  EXPECT_EQ(alarm_type_name(0x0090), "reserved for profiles");
  EXPECT_EQ(alarm_type_name(0x0000), "reserved");
  EXPECT_EQ(alarm_type_name(0x0016), "reserved");
  EXPECT_EQ(user_structure_name(0x8002), "ExtChannelDiagnosis");
  EXPECT_EQ(user_structure_name(0x1234), "manufacturer specific");
  EXPECT_EQ(user_structure_name(0x9000), "reserved");
  EXPECT_EQ(to_string(RtaPduType::Nack), "NACK-RTA-PDU");
}

TEST(PnAlarm, MalformedRta) {
  EXPECT_EQ(decode_rta(std::span(kRtaAck).first(11)).error, AlarmError::TruncatedRtaHeader);
  EXPECT_EQ(decode_rta(std::span(kAlarmData).first(45)).error, AlarmError::VarPartBeyondPdu);  // length lies
  Bytes b = kRtaAck;
  b[4] = 0x15;  // type 5
  EXPECT_EQ(decode_rta(b).error, AlarmError::UnknownPduType);
  b[4] = 0x10;  // type 0
  EXPECT_EQ(decode_rta(b).error, AlarmError::UnknownPduType);
  b[4] = 0x23;  // version 2
  EXPECT_EQ(decode_rta(b).error, AlarmError::UnsupportedVersion);
  // ACK with a var part, DATA without one, ERR with 3 octets.
  EXPECT_EQ(decode_rta(hex("00 03 00 01 13 01 FF FF 00 00 00 01 00")).error, AlarmError::UnexpectedVarPart);
  EXPECT_EQ(decode_rta(hex("00 03 00 01 11 01 00 00 00 00 00 00")).error, AlarmError::UnexpectedVarPart);
  EXPECT_EQ(decode_rta(hex("00 03 00 01 14 01 00 00 00 00 00 03 CF 81 FD")).error, AlarmError::UnexpectedVarPart);
  // Ethernet padding behind the var part is not part of it.
  Bytes padded = kRtaAck;
  padded.resize(44, 0);
  const RtaView r = decode_rta(padded);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.var_part.empty());
  EXPECT_EQ(rta_error_status(r), RtaPnioStatus{});
}

TEST(PnAlarm, MalformedBlocks) {
  const std::span<const std::uint8_t> notif = std::span(kAlarmData).subspan(12);
  const std::span<const std::uint8_t> ack = std::span(kAckData).subspan(12);
  EXPECT_EQ(decode_alarm_notification(notif.first(5)).error, AlarmError::TruncatedBlockHeader);
  EXPECT_EQ(decode_alarm_ack(ack.first(5)).error, AlarmError::TruncatedBlockHeader);
  EXPECT_EQ(decode_alarm_notification(ack).error, AlarmError::WrongBlockType);
  EXPECT_EQ(decode_alarm_ack(notif).error, AlarmError::WrongBlockType);
  Bytes b(notif.begin(), notif.end());
  b[4] = 2;
  EXPECT_EQ(decode_alarm_notification(b).error, AlarmError::UnsupportedBlockVersion);
  // BlockLength lying in both directions, a truncated block, octets after the block.
  b.assign(notif.begin(), notif.end());
  b[3] = 0x1F;
  EXPECT_EQ(decode_alarm_notification(b).error, AlarmError::BlockLengthMismatch);
  b[3] = 0x1D;
  EXPECT_EQ(decode_alarm_notification(b).error, AlarmError::BlockLengthMismatch);
  EXPECT_EQ(decode_alarm_notification(notif.first(25)).error, AlarmError::BlockLengthMismatch);
  b.assign(notif.begin(), notif.begin() + 26);
  b[3] = 0x16;
  EXPECT_TRUE(decode_alarm_notification(b).ok());
  b[3] = 0x10;  // BlockLength too short for the fixed fields
  b.resize(20);
  EXPECT_EQ(decode_alarm_notification(b).error, AlarmError::BlockLengthMismatch);
  // A lone octet where the UserStructureIdentifier would be.
  b.assign(notif.begin(), notif.begin() + 27);
  b[3] = 0x17;
  EXPECT_EQ(decode_alarm_notification(b).error, AlarmError::BlockLengthMismatch);
  // AlarmAck one octet long and one short.
  b.assign(ack.begin(), ack.end());
  b.push_back(0);
  b[3] = 0x13;
  EXPECT_EQ(decode_alarm_ack(b).error, AlarmError::BlockLengthMismatch);
  b.assign(ack.begin(), ack.end() - 1);
  b[3] = 0x11;
  EXPECT_EQ(decode_alarm_ack(b).error, AlarmError::BlockLengthMismatch);
  EXPECT_EQ(alarm_block_type(notif.first(1)), 0);
  EXPECT_EQ(to_string(AlarmError::BlockLengthMismatch), "alarm BlockLength does not match the octets of the block");
}

TEST(PnAlarm, EncoderRefusals) {
  std::array<std::uint8_t, 1500> buf{};
  AlarmNotification n = diagnosis_alarm();
  EXPECT_EQ(encode_alarm_notification(std::span(buf).first(33), n), 0U);
  n.has_user_structure = false;  // data without its identifier
  EXPECT_EQ(encode_alarm_notification(buf, n), 0U);
  std::array<std::uint8_t, 1460> big{};
  n.has_user_structure = true;
  n.user_data = big;  // 26 + 2 + 1460 > 1486
  EXPECT_EQ(encode_alarm_notification(buf, n), 0U);
  EXPECT_EQ(encode_alarm_ack(std::span(buf).first(21), AlarmAck{}), 0U);
  EXPECT_EQ(encode_rta(std::span(buf).first(11), RtaHeader{}, {}), 0U);
  EXPECT_EQ(encode_rta(buf, RtaHeader{}, std::span(big).first(1487)), 0U);
  RtaHeader bad;
  bad.window_size = 16;
  EXPECT_EQ(encode_rta(buf, bad, {}), 0U);
  EXPECT_FALSE(encode_rta_header(RtaHeader{}, std::span(buf).first(11)));
}

}  // namespace
}  // namespace drivegate::profinet
