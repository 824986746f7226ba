// The alarm path allocates nothing (DESIGN.md §3): 300 alarms of both priorities, with lost frames
// and retransmissions, through the controller's AlarmChannel and the device's AlarmSender, with the
// allocation counter armed (tests/support/alloc_counter.hpp).
#include <gtest/gtest.h>

#include "tests/profinet_alarm/alarm_wire.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet::test {
namespace {

class Counter final : public AlarmListener {
 public:
  void on_alarm(const AlarmEvent& e) noexcept override {
    ++alarms;
    chars += e.text.size();
  }
  std::size_t alarms = 0;
  std::size_t chars = 0;
};

TEST(PnAlarmNoAlloc, ThreeHundredAlarmsWithLosses) {
  Counter counter;
  AlarmChannel controller(channel_config(), &counter);
  AlarmSender device(sender_config());
  controller.open();
  device.open();
  const std::array<std::uint8_t, 12> diagnosis{0x00, 0x03, 0x28, 0x00, 0x00, 0x05, 0x00, 0x01, 0x00, 0x00, 0x00, 0x12};
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  core::TimePoint now{std::chrono::seconds(1)};
  std::size_t frames = 0;

  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 300; ++i) {
    AlarmNotification n = alarm(i % 3 == 0 ? alarm_type::kDiagnosis : alarm_type::kProcess,
                                i % 2 == 0 ? AlarmPriority::High : AlarmPriority::Low);
    n.has_user_structure = true;
    n.user_structure_id = user_structure::kExtChannelDiagnosis;
    n.user_data = diagnosis;
    ASSERT_TRUE(device.send(n));
    // Exchange until both are quiet; every 7th frame is lost.
    for (int step = 0; step < 100; ++step) {
      bool any = false;
      for (int side = 0; side < 2; ++side) {
        while (const std::size_t len = side == 0 ? device.poll(now, buf) : controller.poll(now, buf)) {
          any = true;
          if (++frames % 7 == 0) continue;
          const auto f = std::span<const std::uint8_t>(buf).first(len);
          (void)(side == 0 ? controller.on_frame(f, now) : device.on_frame(f, now));
        }
      }
      if (any) continue;
      const core::TimePoint next = std::min(controller.next_deadline(), device.next_deadline());
      if (next == core::TimePoint::max()) break;
      now = std::max(now, next);
    }
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(counter.alarms, 300U);
  EXPECT_EQ(device.counters().acknowledged, 300U);
  EXPECT_EQ(controller.state(), AlarmChannelState::Open);
  EXPECT_GT(device.rta_counters(AlarmPriority::High).retransmissions + controller.rta_counters(AlarmPriority::Low).retransmissions, 0U);
}

}  // namespace
}  // namespace drivegate::profinet::test
