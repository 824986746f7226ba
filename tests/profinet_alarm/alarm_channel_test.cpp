// The controller's AlarmChannel against the simulated device's AlarmSender on an in-memory cable
// with virtual time: every alarm type the bus reports taken once, acknowledged at both levels,
// with its text; lost DATA, ACK and AlarmAck frames recovered by retransmission; ERR and an
// AlarmAck nobody acknowledges abort; the priorities run independently.
#include <gtest/gtest.h>

#include "tests/profinet_alarm/alarm_wire.hpp"

namespace drivegate::profinet::test {
namespace {

constexpr std::string_view kPlace = "API 0x00000000 slot 1 subslot 0x0001, module 0x00000010 submodule 0x00000011";

std::string line(std::string_view head, std::string_view tail) {
  return std::string(head) + ", " + std::string(kPlace) + ", " + std::string(tail);
}

TEST(PnAlarm, ProcessAlarmIsTakenAndAcknowledgedOnBothLevels) {
  AlarmWire w;
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess)));
  ASSERT_TRUE(w.settle());
  ASSERT_EQ(w.recorder.alarms.size(), 1U);
  EXPECT_EQ(w.recorder.alarms[0].text, line("alarm high: Process (0x0002)", "sequence 0"));
  EXPECT_EQ(w.device.counters().acknowledged, 1U);
  EXPECT_EQ(w.device.last_ack_status(AlarmPriority::High), RtaPnioStatus{});
  EXPECT_EQ(w.controller.counters().alarms, 1U);
  EXPECT_EQ(w.controller.counters().acks_confirmed, 1U);
  // Notification, its ACK, the AlarmAck, its ACK; the sequence numbers of both directions.
  ASSERT_EQ(w.log.size(), 4U);
  const RtaHeader notification = rta_of(w.log[0]).header;
  EXPECT_EQ(notification.type, RtaPduType::Data);
  EXPECT_TRUE(notification.tack);
  EXPECT_EQ(notification.dst_endpoint, kControllerRef);
  EXPECT_EQ(notification.src_endpoint, kDeviceRef);
  EXPECT_EQ(notification.send_seq, 0xFFFF);
  EXPECT_EQ(notification.ack_seq, 0xFFFE);
  const RtaHeader ack = rta_of(w.log[1]).header;
  EXPECT_EQ(ack.type, RtaPduType::Ack);
  EXPECT_FALSE(ack.tack);
  EXPECT_EQ(ack.dst_endpoint, kDeviceRef);
  EXPECT_EQ(ack.src_endpoint, kControllerRef);
  EXPECT_EQ(ack.send_seq, 0xFFFE);
  EXPECT_EQ(ack.ack_seq, 0xFFFF);
  EXPECT_TRUE(is_block(w.log[2], alarm_block::kAckHigh));
  EXPECT_EQ(rta_of(w.log[2]).header.send_seq, 0xFFFF);
  EXPECT_EQ(rta_of(w.log[2]).header.ack_seq, 0xFFFF);
  EXPECT_TRUE(is_pdu(w.log[3], kDeviceMac, RtaPduType::Ack));
  EXPECT_EQ(rta_of(w.log[3]).header.ack_seq, 0xFFFF);
  const AlarmAckView a = decode_alarm_ack(rta_of(w.log[2]).var_part);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.ack.alarm_type, alarm_type::kProcess);
  EXPECT_EQ(a.ack.slot, 1);
  const EthernetView e = decode_ethernet(w.log[2]);
  EXPECT_EQ(e.header.priority, kPriorityAlarmHigh);
  EXPECT_EQ(e.header.dst, kDeviceMac);

  // The next alarm is numbered 0 on both levels.
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess)));
  ASSERT_TRUE(w.settle());
  EXPECT_EQ(rta_of(w.log[4]).header.send_seq, 0);
  EXPECT_EQ(rta_of(w.log[4]).header.ack_seq, 0xFFFF);
  EXPECT_EQ(rta_of(w.log[6]).header.send_seq, 0);
  EXPECT_EQ(w.recorder.alarms[1].text, line("alarm high: Process (0x0002)", "sequence 1"));
}

TEST(PnAlarm, DiagnosisAlarmCarriesItsChannelDiagnosisInTheText) {
  AlarmWire w;
  // ExtChannelDiagnosis: channel 3, input, appears, fault, overtemperature, ext 0001h value 12h;
  // then the whole submodule, output, maintenance required, accumulative, line break.
  const std::array<std::uint8_t, 24> items{0x00, 0x03, 0x28, 0x00, 0x00, 0x05, 0x00, 0x01, 0x00, 0x00, 0x00, 0x12,
                                           0x80, 0x00, 0x4B, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  AlarmNotification n = alarm(alarm_type::kDiagnosis);
  n.specifier.channel_diagnosis = true;
  n.specifier.submodule_diagnosis = true;
  n.specifier.ar_diagnosis = true;
  n.has_user_structure = true;
  n.user_structure_id = user_structure::kExtChannelDiagnosis;
  n.user_data = items;
  ASSERT_TRUE(w.device.send(n));
  ASSERT_TRUE(w.settle());
  ASSERT_EQ(w.recorder.alarms.size(), 1U);
  EXPECT_EQ(w.recorder.alarms[0].text,
            line("alarm high: Diagnosis (0x0001)",
                 "sequence 0, channel diagnosis, submodule has diagnosis, AR has diagnosis; channel 3 (input) "
                 "overtemperature (0x0005), appears, fault, ext 0x0001 value 0x00000012; submodule (output) line break "
                 "(0x0006), appears, maintenance required, accumulative, ext 0x0000 value 0x00000000"));
  EXPECT_EQ(w.controller.counters().bad_channel_diagnosis, 0U);

  // Channel diagnosis data that is not whole entries: the alarm is taken, the text says so.
  const std::array<std::uint8_t, 5> odd{0x00, 0x01, 0x28, 0x00, 0x00};
  n.user_structure_id = user_structure::kChannelDiagnosis;
  n.user_data = odd;
  ASSERT_TRUE(w.device.send(n));
  // Manufacturer data: named with its USI and length.
  n.user_structure_id = 0x0100;
  ASSERT_TRUE(w.device.send(n));
  ASSERT_TRUE(w.settle());
  ASSERT_EQ(w.recorder.alarms.size(), 3U);
  EXPECT_NE(w.recorder.alarms[1].text.find("; ChannelDiagnosis data not readable: " +
                                           std::string(to_string(AlarmError::ChannelDiagnosisLength))),
            std::string::npos)
      << w.recorder.alarms[1].text;
  EXPECT_NE(w.recorder.alarms[2].text.find("AR has diagnosis; manufacturer specific (USI 0x0100), 5 octets"),
            std::string::npos)
      << w.recorder.alarms[2].text;
  EXPECT_EQ(w.controller.counters().bad_channel_diagnosis, 1U);
  EXPECT_EQ(w.device.counters().acknowledged, 3U);
}

TEST(PnAlarm, PullPlugAndReturnOfSubmoduleInOrder) {
  AlarmWire w;
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kPull, AlarmPriority::Low, 2, 1)));
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kPlug, AlarmPriority::Low, 2, 1)));
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kReturnOfSubmodule, AlarmPriority::Low, 2, 1)));
  ASSERT_TRUE(w.settle());
  ASSERT_EQ(w.recorder.alarms.size(), 3U);
  const std::string place = ", API 0x00000000 slot 2 subslot 0x0001, module 0x00000010 submodule 0x00000011, sequence ";
  EXPECT_EQ(w.recorder.alarms[0].text, "alarm low: Pull (0x0003)" + place + "0");
  EXPECT_EQ(w.recorder.alarms[1].text, "alarm low: Plug (0x0004)" + place + "1");
  EXPECT_EQ(w.recorder.alarms[2].text, "alarm low: Return of submodule (0x000B)" + place + "2");
  EXPECT_EQ(w.device.counters().acknowledged, 3U);
  for (const Bytes& f : w.log) {
    const EthernetView e = decode_ethernet(f);
    EXPECT_EQ(e.header.frame_id, frame_id::kAlarmLow);
    EXPECT_EQ(e.header.priority, kPriorityAlarmLow);
  }
  EXPECT_EQ(w.log.size(), 12U);  // nothing sent twice
}

TEST(PnAlarm, LostNotificationIsSentAgainAfterTheRtaTimeout) {
  AlarmWire w;
  int lost = 0;
  w.drop = [&](std::span<const std::uint8_t> f) {
    return lost == 0 && is_block(f, alarm_block::kNotificationHigh) && ++lost == 1;
  };
  const core::TimePoint start = w.now;
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess)));
  ASSERT_TRUE(w.run_until([&] { return w.recorder.alarms.size() == 1; }));
  EXPECT_EQ(w.now - start, 100ms);
  ASSERT_TRUE(w.settle());
  EXPECT_EQ(w.recorder.alarms.size(), 1U);
  EXPECT_EQ(w.device.rta_counters(AlarmPriority::High).retransmissions, 1U);
  EXPECT_EQ(w.device.counters().acknowledged, 1U);
}

TEST(PnAlarm, LostAckMakesADuplicateThatIsAcknowledgedAgainNotTakenTwice) {
  AlarmWire w;
  // The controller's ACK and its first AlarmAck (which would acknowledge too) are lost: the device
  // sends the notification again.
  int acks = 0;
  int alarm_acks = 0;
  w.drop = [&](std::span<const std::uint8_t> f) {
    if (is_pdu(f, kControllerMac, RtaPduType::Ack)) return ++acks == 1;
    if (is_block(f, alarm_block::kAckHigh)) return ++alarm_acks == 1;
    return false;
  };
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess)));
  ASSERT_TRUE(w.settle());
  EXPECT_EQ(w.recorder.alarms.size(), 1U);
  const RtaCounters& c = w.controller.rta_counters(AlarmPriority::High);
  EXPECT_EQ(c.taken, 1U);
  EXPECT_EQ(c.duplicates, 1U);
  EXPECT_EQ(c.acks_sent, 2U);
  EXPECT_EQ(w.device.rta_counters(AlarmPriority::High).retransmissions, 1U);
  EXPECT_EQ(w.device.counters().acknowledged, 1U);
  EXPECT_EQ(w.controller.counters().acks_confirmed, 1U);
}

TEST(PnAlarm, LostAlarmAckIsSentAgain) {
  AlarmWire w;
  int alarm_acks = 0;
  w.drop = [&](std::span<const std::uint8_t> f) { return is_block(f, alarm_block::kAckHigh) && ++alarm_acks == 1; };
  const core::TimePoint start = w.now;
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess)));
  ASSERT_TRUE(w.run_until([&] { return w.device.counters().acknowledged == 1; }));
  EXPECT_EQ(w.now - start, 100ms);
  EXPECT_EQ(w.controller.rta_counters(AlarmPriority::High).retransmissions, 1U);
  EXPECT_EQ(w.device.rta_counters(AlarmPriority::High).retransmissions, 0U);  // its ACK came
  EXPECT_EQ(w.recorder.alarms.size(), 1U);
  ASSERT_TRUE(w.settle());
  EXPECT_EQ(w.controller.counters().acks_confirmed, 1U);
}

TEST(PnAlarm, ErrFromTheDeviceAbortsWithTheReason) {
  AlarmWire w;
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess)));
  ASSERT_TRUE(w.settle());
  w.device.abort(RtaPnioStatus{0xCF, 0x81, 0xFD, 13});
  ASSERT_TRUE(w.run_until([&] { return w.controller.state() == AlarmChannelState::Aborted; }));
  EXPECT_EQ(w.controller.reason(),
            "alarm low: the device aborted the alarm CR (ERR-RTA-PDU): RTA error PNIO: RTA protocol error: AR abort "
            "request (CF 81 FD 0D)");
  EXPECT_EQ(w.controller.rta_counters(AlarmPriority::Low).errors_received, 1U);
  // Nothing more is taken until the next AR.
  const Bytes first = w.log[0];
  w.inject(first);
  EXPECT_EQ(w.controller.counters().inactive, 1U);
  EXPECT_EQ(w.recorder.alarms.size(), 1U);
  EXPECT_EQ(w.controller.next_deadline(), core::TimePoint::max());
}

TEST(PnAlarm, AnAlarmAckNeverAcknowledgedAbortsAndTellsTheDevice) {
  AlarmWire w;
  w.drop = [&](std::span<const std::uint8_t> f) { return is_pdu(f, kDeviceMac, RtaPduType::Ack); };
  const core::TimePoint start = w.now;
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kDiagnosis, AlarmPriority::High, 1, 0x8001)));
  ASSERT_TRUE(w.run_until([&] { return w.controller.state() == AlarmChannelState::Aborted; }));
  EXPECT_EQ(w.now - start, 4 * 100ms);  // 1 + 3 retries, 100 ms each
  EXPECT_EQ(w.controller.reason(),
            "alarm high: the AlarmAck of the Diagnosis alarm (slot 1 subslot 0x8001, sequence 0) was not acknowledged "
            "after 4 frames (RTA timeout 100 ms, 3 retries); ERR sent to the device (CF 81 FD 09)");
  const RtaCounters& c = w.controller.rta_counters(AlarmPriority::High);
  EXPECT_EQ(c.data_sent, 1U);
  EXPECT_EQ(c.retransmissions, 3U);
  EXPECT_EQ(c.errors_sent, 1U);
  ASSERT_TRUE(w.run_until([&] { return w.device.state() == AlarmSenderState::Aborted; }));
  EXPECT_EQ(w.device.reason(),
            "the controller aborted the alarm CR (ERR-RTA-PDU): RTA error PNIO: RTA protocol error: AR "
            "alarm-ack-send.cnf(-) (CF 81 FD 09)");
  EXPECT_EQ(w.device.rta_counters(AlarmPriority::High).duplicates, 3U);  // every AlarmAck again: re-ACKed
}

TEST(PnAlarm, DeviceWithoutAnyAckAbortsAfterItsRetries) {
  AlarmWire w;
  w.drop = [&](std::span<const std::uint8_t> f) { return decode_ethernet(f).header.src == kDeviceMac; };
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess)));
  ASSERT_TRUE(w.run_until([&] { return w.device.state() == AlarmSenderState::Aborted; }));
  EXPECT_EQ(w.device.reason(), "alarm high: no ACK from the controller after 4 frames; ERR sent (CF 81 FD 08)");
  EXPECT_TRUE(w.recorder.alarms.empty());
}

TEST(PnAlarm, HighAndLowRunIndependently) {
  AlarmWire w;
  // The low channel's frames are lost for 250 ms: the high alarm goes through meanwhile.
  const core::TimePoint until = w.now + 250ms;
  w.drop = [&](std::span<const std::uint8_t> f) {
    return decode_ethernet(f).header.frame_id == frame_id::kAlarmLow && w.now < until;
  };
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kPull, AlarmPriority::Low)));
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess, AlarmPriority::High)));
  ASSERT_TRUE(w.settle());
  ASSERT_EQ(w.recorder.alarms.size(), 2U);
  EXPECT_EQ(w.recorder.alarms[0].n.priority, AlarmPriority::High);
  EXPECT_EQ(w.recorder.alarms[1].n.priority, AlarmPriority::Low);
  EXPECT_EQ(w.recorder.alarms[0].n.specifier.sequence, 0);  // each priority counts its own
  EXPECT_EQ(w.recorder.alarms[1].n.specifier.sequence, 0);
  EXPECT_EQ(w.device.rta_counters(AlarmPriority::Low).retransmissions, 3U);  // at 100, 200, 300 ms
  EXPECT_EQ(w.device.rta_counters(AlarmPriority::High).retransmissions, 0U);
  EXPECT_EQ(w.device.counters().acknowledged, 2U);
}

TEST(PnAlarm, AlarmCrOutsideItsRangesIsRefused) {
  AlarmChannelConfig c = channel_config();
  c.alarm_cr.rta_timeout_factor = 0;
  AlarmChannel timeout(c);
  EXPECT_EQ(timeout.error(), AlarmCrError::BadTimeoutFactor);
  timeout.open();
  EXPECT_EQ(timeout.state(), AlarmChannelState::Closed);
  c.alarm_cr.rta_timeout_factor = 101;
  EXPECT_EQ(AlarmChannel(c).error(), AlarmCrError::BadTimeoutFactor);
  c = channel_config();
  c.alarm_cr.rta_retries = 2;
  EXPECT_EQ(AlarmChannel(c).error(), AlarmCrError::BadRetries);
  c.alarm_cr.rta_retries = 16;
  EXPECT_EQ(AlarmChannel(c).error(), AlarmCrError::BadRetries);
  EXPECT_EQ(to_string(AlarmCrError::BadRetries), "RTARetries outside 3..15");
  c.alarm_cr.rta_retries = 15;
  c.alarm_cr.rta_timeout_factor = 100;
  EXPECT_TRUE(AlarmChannel(c).ok());
}

}  // namespace
}  // namespace drivegate::profinet::test
