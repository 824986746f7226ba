// A whole alarm exchange of the engines dissects cleanly in tshark (tests/support/pcap.hpp): a high
// diagnosis alarm with ExtChannelDiagnosis and a low pull alarm, each with the transport ACKs and
// the AlarmAck, one lost and retransmitted notification, then the device's ERR. No "Malformed", no
// expert warning or error. Skipped when tshark is missing.
#include <gtest/gtest.h>

#include <string>

#include "tests/profinet_alarm/alarm_wire.hpp"
#include "tests/support/pcap.hpp"

namespace drivegate::profinet::test {
namespace {

TEST(PnAlarmTshark, ExchangeDissectsCleanly) {
  AlarmWire w;
  int lost = 0;
  w.drop = [&](std::span<const std::uint8_t> f) { return is_block(f, alarm_block::kNotificationLow) && ++lost == 1; };
  const std::array<std::uint8_t, 12> items{0x00, 0x03, 0x28, 0x00, 0x00, 0x05, 0x00, 0x01, 0x00, 0x00, 0x00, 0x12};
  AlarmNotification diag = alarm(alarm_type::kDiagnosis);
  diag.specifier.channel_diagnosis = true;
  diag.specifier.submodule_diagnosis = true;
  diag.specifier.ar_diagnosis = true;
  diag.has_user_structure = true;
  diag.user_structure_id = user_structure::kExtChannelDiagnosis;
  diag.user_data = items;
  ASSERT_TRUE(w.device.send(diag));
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kPull, AlarmPriority::Low, 2, 1)));
  ASSERT_TRUE(w.settle());
  w.device.abort(RtaPnioStatus{0xCF, 0x81, 0xFD, 13});
  ASSERT_TRUE(w.run_until([&] { return w.controller.state() == AlarmChannelState::Aborted; }));
  ASSERT_EQ(w.log.size(), 10U);  // 2 × (notification, ACK, AlarmAck, ACK), a retransmission, ERR

  const std::optional<std::string> text = drivegate::test::tshark_dissect(w.log);
  if (!text) GTEST_SKIP() << "tshark is not installed";
  EXPECT_EQ(text->find("Malformed"), std::string::npos) << *text;
  EXPECT_EQ(text->find("Expert Info (Error"), std::string::npos) << *text;
  EXPECT_EQ(text->find("Expert Info (Warning"), std::string::npos) << *text;
  for (const char* field : {"Alarm High, ID:0xfc01", "Alarm Low, ID:0xfe01", "Type: Data-RTA-PDU (0x1)",
                            "Type: ACK-RTA-PDU (0x3)", "Type: ERR-RTA-PDU (0x4)",
                            "BlockType: Alarm Notification High (0x0001)", "BlockType: Alarm Ack High (0x8001)",
                            "BlockType: Alarm Notification Low (0x0002)", "BlockType: Alarm Ack Low (0x8002)",
                            "AlarmType: Diagnosis (0x0001)", "AlarmType: Pull (0x0003)", "PRI: 5"}) {
    EXPECT_NE(text->find(field), std::string::npos) << "missing: " << field << "\n" << *text;
  }
}

}  // namespace
}  // namespace drivegate::profinet::test
