// The codecs allocate nothing (DESIGN.md §3: no heap in the cyclic path): a cycle's RT output frame
// built and an input frame checked, a DCP identify exchange, and an alarm notification with its
// acknowledgement, all with the allocation counter armed (tests/support/alloc_counter.hpp).
#include <gtest/gtest.h>

#include <array>

#include "adapters/profinet/wire/alarm.hpp"
#include "adapters/profinet/wire/dcp.hpp"
#include "adapters/profinet/wire/ethernet.hpp"
#include "adapters/profinet/wire/rt.hpp"
#include "adapters/profinet/wire/station_name.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet {
namespace {

constexpr MacAddress kController{0x02, 0, 0, 0, 0, 1};
constexpr MacAddress kDevice{0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};

TEST(PnNoAlloc, CyclicExchange) {
  const std::array<IoSubmodule, 3> subs{{{IoKind::NoIo, 0, 0}, {IoKind::InputOutput, 10, 10}, {IoKind::Input, 4, 0}}};
  std::array<IoPlacement, 3> out_place{};
  std::array<IoPlacement, 3> in_place{};
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  std::array<std::uint8_t, kMaxCsduLength> c_sdu{};
  std::size_t ok = 0;
  const test::AllocationScope scope;
  const CsduLayout out_l = compute_csdu_layout(CrDirection::Output, subs, out_place);
  const CsduLayout in_l = compute_csdu_layout(CrDirection::Input, subs, in_place);
  for (std::uint16_t cycle = 1; cycle <= 100; ++cycle) {
    EthernetHeader h;
    h.dst = kDevice;
    h.src = kController;
    h.vlan = true;
    h.priority = kPriorityRtCyclic;
    h.frame_id = 0x8001;
    const std::size_t at = encode_ethernet_header(h, buf);
    c_sdu[out_place[1].data_offset] = static_cast<std::uint8_t>(cycle);
    ApduStatus s;
    s.cycle_counter = static_cast<std::uint16_t>(cycle * 32);
    const std::size_t n = encode_rt_cyclic(std::span(buf).subspan(at), std::span(c_sdu).first(out_l.used), out_l.length, s);
    const std::size_t size = pad_frame(buf, at + n);
    // The device's answer has the same shape: read it back as an input frame.
    const EthernetView e = decode_ethernet(std::span<const std::uint8_t>(buf).first(size));
    const RtInputCheck c = check_input_frame(e.header.frame_id, e.pdu, 0x8001, in_l.length, cycle > 1,
                                             static_cast<std::uint16_t>((cycle - 1) * 32));
    if (c.result == RtCheck::Ok) ++ok;
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(ok, 100U);
}

TEST(PnNoAlloc, DcpAndAlarm) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  std::array<std::uint8_t, kMaxFrameSize> req{};
  std::array<DcpSetResult, 4> results{};
  std::size_t good = 0;
  const test::AllocationScope scope;
  for (int i = 0; i < 20; ++i) {
    std::size_t n = encode_identify_name_request(req, 1, 1, "akd-1");
    const DcpIdentifyFilter f = decode_identify_request(decode_dcp(std::span<const std::uint8_t>(req).first(n)));
    DcpDeviceInfo d;
    d.has_name_of_station = true;
    d.name_of_station = f.name_of_station;
    d.has_ip = true;
    n = encode_identify_response(buf, 1, d);
    const DcpDeviceInfoView v = decode_device_info(decode_dcp(std::span<const std::uint8_t>(buf).first(n)));
    const bool named = v.error == DcpError::None && validate_name_of_station(v.info.name_of_station) == NameError::None &&
                       v.info.name_of_station == "akd-1";
    const std::array<DcpSetResult, 1> r{{{dcp_option::kIpParameter, DcpBlockError::NoError}}};
    n = encode_set_response(buf, 2, r);
    const DcpSetResponse s = decode_set_response(decode_dcp(std::span<const std::uint8_t>(buf).first(n)), results);
    AlarmNotification a;
    a.alarm_type = alarm_type::kProcess;
    const std::size_t block = encode_alarm_notification(std::span(buf).subspan(kRtaHeaderSize), a);
    n = encode_rta(buf, RtaHeader{}, std::span(buf).subspan(kRtaHeaderSize, block));
    const RtaView rta = decode_rta(std::span<const std::uint8_t>(buf).first(n));
    const AlarmNotificationView an = decode_alarm_notification(rta.var_part);
    n = encode_alarm_ack(buf, ack_for(an.notification));
    const AlarmAckView ack = decode_alarm_ack(std::span<const std::uint8_t>(buf).first(n));
    if (named && s.all_ok() && ack.ok()) {
      ++good;
    }
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(good, 20U);
}

}  // namespace
}  // namespace drivegate::profinet
