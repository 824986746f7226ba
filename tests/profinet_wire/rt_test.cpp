// RT class 1 cyclic frames [IEC 61158-6-10: the RT frame's C_SDU and APDU_Status (CycleCounter,
// DataStatus, TransferStatus); §4.7.2.1.2, the CPM's cycle counter and receive checks].
#include "adapters/profinet/wire/rt.hpp"

#include <gtest/gtest.h>

#include <array>

#include "adapters/profinet/wire/ethernet.hpp"
#include "tests/profinet_wire/bytes.hpp"

namespace drivegate::profinet {
namespace {

using test::Bytes;
using test::hex;

TEST(PnRt, DataStatusBits) {
  EXPECT_EQ(data_status::kGood, 0x35);
  ApduStatus s;
  s.data_status = 0x35;
  EXPECT_TRUE(s.primary());
  EXPECT_TRUE(s.data_valid());
  EXPECT_TRUE(s.provider_run());
  EXPECT_FALSE(s.station_problem());
  EXPECT_FALSE(s.ignore());
  s.data_status = 0x84;  // ignore, valid, backup, STOP, station problem
  EXPECT_FALSE(s.primary());
  EXPECT_TRUE(s.data_valid());
  EXPECT_FALSE(s.provider_run());
  EXPECT_TRUE(s.station_problem());
  EXPECT_TRUE(s.ignore());
  EXPECT_TRUE(iox_status::is_good(iox_status::kGood));
  EXPECT_FALSE(iox_status::is_good(iox_status::kBadByController));
}

TEST(PnRt, CycleCounter) {
  EXPECT_EQ(cycle_counter_at(0), 0);
  EXPECT_EQ(cycle_counter_at(1'000'000), 32);  // 1 ms = 32 × 31.25 µs
  EXPECT_EQ(cycle_counter_at(2'048'000'000ULL), 0);  // 65536 × 31.25 µs wraps
  // The CPM's window: step 1..61440 is new data.
  EXPECT_FALSE(cycle_counter_advanced(1, 1));
  EXPECT_TRUE(cycle_counter_advanced(1, 2));
  EXPECT_FALSE(cycle_counter_advanced(1, 0));
  EXPECT_FALSE(cycle_counter_advanced(1, 0xFFFF));
  EXPECT_TRUE(cycle_counter_advanced(0xFFE0, 0x0000));  // across the wrap
  EXPECT_TRUE(cycle_counter_advanced(0x4000, 0x0000));  // step 0xC000 = 49152
  EXPECT_TRUE(cycle_counter_advanced(0x0000, 0xF000));  // step 61440, the largest
  EXPECT_FALSE(cycle_counter_advanced(0x0000, 0xF001));
}

// DAP (no IO), a telegram-1-like submodule (4 octets each way), an input and an output module.
constexpr std::array<IoSubmodule, 4> kSubmodules{{
    {IoKind::NoIo, 0, 0},
    {IoKind::InputOutput, 4, 4},
    {IoKind::Input, 2, 0},
    {IoKind::Output, 0, 3},
}};

TEST(PnRt, InputCrLayout) {
  std::array<IoPlacement, 4> p{};
  const CsduLayout l = compute_csdu_layout(CrDirection::Input, kSubmodules, p);
  ASSERT_TRUE(l.ok()) << to_string(l.error);
  // data + IOPS in submodule order, then the IOCS of the submodules with outputs.
  EXPECT_EQ(p[0].data_offset, 0);
  EXPECT_EQ(p[0].data_length, 0);
  EXPECT_EQ(p[0].iops_offset, 0);
  EXPECT_EQ(p[0].iocs_offset, kNoOffset);
  EXPECT_EQ(p[1].data_offset, 1);
  EXPECT_EQ(p[1].iops_offset, 5);
  EXPECT_EQ(p[1].iocs_offset, 9);
  EXPECT_EQ(p[2].data_offset, 6);
  EXPECT_EQ(p[2].iops_offset, 8);
  EXPECT_EQ(p[2].iocs_offset, kNoOffset);
  EXPECT_EQ(p[3].data_offset, kNoOffset);
  EXPECT_EQ(p[3].iops_offset, kNoOffset);
  EXPECT_EQ(p[3].iocs_offset, 10);
  EXPECT_EQ(l.used, 11);
  EXPECT_EQ(l.length, 40);
}

TEST(PnRt, OutputCrLayout) {
  std::array<IoPlacement, 4> p{};
  const CsduLayout l = compute_csdu_layout(CrDirection::Output, kSubmodules, p);
  ASSERT_TRUE(l.ok());
  EXPECT_EQ(p[0].data_offset, kNoOffset);
  EXPECT_EQ(p[0].iocs_offset, 9);
  EXPECT_EQ(p[1].data_offset, 0);
  EXPECT_EQ(p[1].data_length, 4);
  EXPECT_EQ(p[1].iops_offset, 4);
  EXPECT_EQ(p[1].iocs_offset, 10);
  EXPECT_EQ(p[2].data_offset, kNoOffset);
  EXPECT_EQ(p[2].iocs_offset, 11);
  EXPECT_EQ(p[3].data_offset, 5);
  EXPECT_EQ(p[3].data_length, 3);
  EXPECT_EQ(p[3].iops_offset, 8);
  EXPECT_EQ(p[3].iocs_offset, kNoOffset);
  EXPECT_EQ(l.used, 12);
  EXPECT_EQ(l.length, 40);
}

TEST(PnRt, LayoutLimits) {
  std::array<IoPlacement, 2> p{};
  // 1439 octets + IOPS = 1440 fits exactly; one more octet does not.
  const std::array<IoSubmodule, 1> full{{{IoKind::Input, 1439, 0}}};
  const CsduLayout l = compute_csdu_layout(CrDirection::Input, full, p);
  ASSERT_TRUE(l.ok());
  EXPECT_EQ(l.length, 1440);
  const std::array<IoSubmodule, 1> over{{{IoKind::Input, 1440, 0}}};
  EXPECT_EQ(compute_csdu_layout(CrDirection::Input, over, p).error, LayoutError::TooLong);
  // The IOCS that does not fit any more.
  const std::array<IoSubmodule, 2> iocs_over{{{IoKind::Input, 1439, 0}, {IoKind::Output, 0, 1}}};
  EXPECT_EQ(compute_csdu_layout(CrDirection::Input, iocs_over, p).error, LayoutError::TooLong);
  EXPECT_EQ(compute_csdu_layout(CrDirection::Input, kSubmodules, p).error, LayoutError::TooFewPlacements);
  const std::array<IoSubmodule, 1> bad{{{IoKind::Output, 2, 0}}};
  EXPECT_EQ(compute_csdu_layout(CrDirection::Input, bad, p).error, LayoutError::BadSubmodule);
  const std::array<IoSubmodule, 1> bad_noio{{{IoKind::NoIo, 1, 0}}};
  EXPECT_EQ(compute_csdu_layout(CrDirection::Output, bad_noio, p).error, LayoutError::BadSubmodule);
}

// The output frame of the telegram-1-like layout: STW1 047Fh, NSOLL_A 4000h (big-endian words),
// every IOPS/IOCS good, priority tag 6, FrameID 8001h, cycle counter 1234h, DataStatus 35h.
const Bytes kOutputFrame = hex(
    "00 1B 1B 12 34 56  02 00 00 00 00 01  81 00 C0 00  88 92  80 01"
    "04 7F 40 00 80  00 00 00 80  80 80 80"   // IO data + IOPS, output data + IOPS, 3 × IOCS
    "00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00"  // to 40
    "12 34 35 00");

TEST(PnRt, OutputFrameBytes) {
  std::array<IoPlacement, 4> p{};
  const CsduLayout l = compute_csdu_layout(CrDirection::Output, kSubmodules, p);
  ASSERT_TRUE(l.ok());
  std::array<std::uint8_t, 40> c_sdu{};
  const std::array<std::uint8_t, 4> telegram{0x04, 0x7F, 0x40, 0x00};
  std::copy(telegram.begin(), telegram.end(), c_sdu.begin() + p[1].data_offset);
  for (const IoPlacement& q : p) {
    if (q.iops_offset != kNoOffset) c_sdu[q.iops_offset] = iox_status::kGood;
    if (q.iocs_offset != kNoOffset) c_sdu[q.iocs_offset] = iox_status::kGood;
  }
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  EthernetHeader h;
  h.dst = {0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};
  h.src = {0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
  h.vlan = true;
  h.priority = kPriorityRtCyclic;
  h.frame_id = 0x8001;
  const std::size_t at = encode_ethernet_header(h, buf);
  ApduStatus s;
  s.cycle_counter = 0x1234;
  const std::size_t n = encode_rt_cyclic(std::span(buf).subspan(at), std::span(c_sdu).first(l.used), l.length, s);
  ASSERT_EQ(n, 44U);
  const std::size_t size = pad_frame(buf, at + n);
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(size)), kOutputFrame);
  // And back.
  const EthernetView e = decode_ethernet(kOutputFrame);
  ASSERT_TRUE(e.ok());
  ASSERT_EQ(e.frame_class, FrameClass::RtCyclic);
  const RtCyclicView v = decode_rt_cyclic(e.pdu, 40);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.status, s);
  EXPECT_EQ(v.c_sdu.size(), 40U);
  EXPECT_EQ(v.c_sdu.data(), kOutputFrame.data() + 20);
}

TEST(PnRt, EncoderRefusals) {
  std::array<std::uint8_t, 1500> buf{};
  std::array<std::uint8_t, 41> c_sdu{};
  EXPECT_EQ(encode_rt_cyclic(buf, {}, 39, {}), 0U);
  EXPECT_EQ(encode_rt_cyclic(buf, {}, 1441, {}), 0U);
  EXPECT_EQ(encode_rt_cyclic(buf, c_sdu, 40, {}), 0U);
  EXPECT_EQ(encode_rt_cyclic(std::span(buf).first(43), {}, 40, {}), 0U);
  EXPECT_EQ(encode_rt_cyclic(std::span(buf).first(44), {}, 40, {}), 44U);
  EXPECT_EQ(encode_rt_cyclic(buf, {}, 1440, {}), 1444U);
}

TEST(PnRt, MalformedFrames) {
  const std::span<const std::uint8_t> pdu = std::span(kOutputFrame).subspan(20);
  EXPECT_EQ(decode_rt_cyclic(pdu, 39).error, RtError::BadCsduLength);
  EXPECT_EQ(decode_rt_cyclic(pdu, 1441).error, RtError::BadCsduLength);
  EXPECT_EQ(decode_rt_cyclic(pdu.first(43), 40).error, RtError::Truncated);
  EXPECT_EQ(decode_rt_cyclic(pdu, 42).error, RtError::Truncated);  // the IOCR length says more than arrived
  EXPECT_TRUE(decode_rt_cyclic(pdu, 40).ok());
  EXPECT_EQ(to_string(RtError::Truncated), "RT frame shorter than its C_SDU and APDU status");
}

Bytes input_pdu(std::uint16_t counter, std::uint8_t data_status, std::uint8_t transfer = 0) {
  Bytes b(44, 0);
  b[40] = static_cast<std::uint8_t>(counter >> 8);
  b[41] = static_cast<std::uint8_t>(counter & 0xFF);
  b[42] = data_status;
  b[43] = transfer;
  return b;
}

TEST(PnRt, InputCheckReasons) {
  const auto check = [](const Bytes& pdu, bool has_last = true, std::uint16_t id = 0x8002) {
    return check_input_frame(id, pdu, 0x8002, 40, has_last, 0x0100);
  };
  EXPECT_EQ(check(input_pdu(0x0120, 0x35)).result, RtCheck::Ok);
  EXPECT_EQ(check(input_pdu(0x0100, 0x35), false).result, RtCheck::Ok);  // the first frame: no counter check
  EXPECT_EQ(check(input_pdu(0x0120, 0x35), true, 0x8003).result, RtCheck::WrongFrameId);
  EXPECT_EQ(check(Bytes(43, 0)).result, RtCheck::Truncated);
  EXPECT_EQ(check(input_pdu(0x0120, 0x35, 1)).result, RtCheck::TransferError);
  EXPECT_EQ(check(input_pdu(0x0100, 0x35)).result, RtCheck::RepeatedCycle);
  EXPECT_EQ(check(input_pdu(0x00E0, 0x35)).result, RtCheck::OldCycle);
  EXPECT_EQ(check(input_pdu(0x0120, 0xB5)).result, RtCheck::Ignore);
  EXPECT_EQ(check(input_pdu(0x0120, 0x31)).result, RtCheck::DataInvalid);
  EXPECT_EQ(check(input_pdu(0x0120, 0x34)).result, RtCheck::Backup);
  EXPECT_EQ(check(input_pdu(0x0120, 0x25)).result, RtCheck::ProviderStop);
  const RtInputCheck problem = check(input_pdu(0x0120, 0x15));
  EXPECT_EQ(problem.result, RtCheck::Ok);
  EXPECT_TRUE(problem.station_problem);
  EXPECT_EQ(problem.frame.status.cycle_counter, 0x0120);
  EXPECT_TRUE(is_frame_error(RtCheck::OldCycle));
  EXPECT_FALSE(is_frame_error(RtCheck::ProviderStop));
  EXPECT_EQ(to_string(RtCheck::RepeatedCycle), "cycle counter did not advance (repeated frame)");
}

}  // namespace
}  // namespace drivegate::profinet
