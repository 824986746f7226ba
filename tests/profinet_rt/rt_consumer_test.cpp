// RtConsumer: input frames taken or refused for every reason, each counted; DataStatus and IOPS
// per submodule reported; the data-hold watchdog expiring at exactly DataHoldFactor × period
// after the last valid frame (not a nanosecond before), with its text, and staying expired until
// the consumer is armed again.
#include <gtest/gtest.h>

#include <string>

#include "tests/profinet_rt/rt_fixture.hpp"

namespace drivegate::profinet::test {
namespace {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;

const core::TimePoint kArm{std::chrono::seconds(7)};
constexpr milliseconds kPeriod{2};
constexpr milliseconds kHold{6};  // 3 × 2 ms

constexpr std::uint8_t without(std::uint8_t bit) { return static_cast<std::uint8_t>(data_status::kGood & ~bit); }

struct PnRtConsumer : ::testing::Test {
  RtConsumer c{iocr(kInputFrameId)};
  core::TimePoint now = kArm;
  std::uint16_t cycle = 100;

  void SetUp() override {
    ASSERT_TRUE(c.ok());
    ASSERT_EQ(c.data_hold_time(), kHold);
    c.arm(now);
  }
  // The next frame one period later, with the next cycle counter.
  bool next(InputFrame f = {}) {
    now += kPeriod;
    cycle = static_cast<std::uint16_t>(cycle + 64);
    f.cycle = cycle;
    return c.on_frame(input_frame(f), now);
  }
};

TEST_F(PnRtConsumer, TakesValidFramesAndReportsData) {
  EXPECT_EQ(c.state(), RtConsumerState::Waiting);
  EXPECT_FALSE(c.all_iops_good());  // nothing received yet
  ASSERT_TRUE(next());
  EXPECT_EQ(c.state(), RtConsumerState::Running);
  EXPECT_EQ(c.counters().frames, 1U);
  EXPECT_EQ(c.status().cycle_counter, cycle);
  EXPECT_EQ(Bytes(c.data(kDrive).begin(), c.data(kDrive).end()), (Bytes{0x11, 0x22, 0x33, 0x44}));
  EXPECT_EQ(Bytes(c.data(kSensor).begin(), c.data(kSensor).end()), (Bytes{0xAB, 0xCD}));
  EXPECT_TRUE(c.data(0).empty());
  EXPECT_EQ(c.iops(kDrive), iox_status::kGood);
  EXPECT_EQ(c.iocs(kDrive), iox_status::kGood);  // the device consumes our output data
  EXPECT_TRUE(c.all_iops_good());
  EXPECT_TRUE(c.provider_run());
  EXPECT_FALSE(c.station_problem());
  EXPECT_EQ(c.next_deadline(), now + kHold);
}

TEST_F(PnRtConsumer, BadIopsOnOneSubmoduleIsReported) {
  ASSERT_TRUE(next({.sensor_iops = iox_status::kBadByDevice}));
  EXPECT_EQ(c.counters().frames, 1U);
  EXPECT_EQ(c.iops(kDrive), iox_status::kGood);
  EXPECT_EQ(c.iops(kSensor), iox_status::kBadByDevice);
  EXPECT_FALSE(c.all_iops_good());
  ASSERT_TRUE(next());
  EXPECT_TRUE(c.all_iops_good());
}

TEST_F(PnRtConsumer, ProviderStopAndStationProblemAreTakenAndReported) {
  ASSERT_TRUE(next({.data_status = without(data_status::kProviderRun)}));
  EXPECT_EQ(c.counters().frames, 1U);
  EXPECT_EQ(c.counters().provider_stop, 1U);
  EXPECT_FALSE(c.provider_run());
  EXPECT_EQ(c.state(), RtConsumerState::Running);
  ASSERT_TRUE(next({.data_status = without(data_status::kStationOk)}));
  EXPECT_TRUE(c.provider_run());
  EXPECT_TRUE(c.station_problem());
  EXPECT_EQ(c.counters().station_problem, 1U);
}

TEST_F(PnRtConsumer, RefusesFramesPerReason) {
  ASSERT_TRUE(next());
  const std::uint16_t good = cycle;
  const core::TimePoint valid_at = now;
  // Another CR's FrameID: not taken. Other traffic (DCP) and garbage: not taken.
  EXPECT_FALSE(c.on_frame(input_frame({.cycle = 1, .frame_id = 0x8003}), now));
  EXPECT_EQ(c.counters().wrong_frame_id, 1U);
  Bytes dcp = input_frame({});
  dcp[18] = 0xFE;
  dcp[19] = 0xFE;
  EXPECT_FALSE(c.on_frame(dcp, now));
  EXPECT_FALSE(c.on_frame(Bytes(10, 0), now));
  EXPECT_EQ(c.counters().malformed, 1U);
  // This FrameID from another station.
  EXPECT_TRUE(c.on_frame(input_frame({.cycle = 9, .source = kController}), now));
  EXPECT_EQ(c.counters().wrong_source, 1U);
  // Repeated and old cycle counters.
  EXPECT_TRUE(c.on_frame(input_frame({.cycle = good}), now));
  EXPECT_EQ(c.counters().repeated_cycle, 1U);
  EXPECT_TRUE(c.on_frame(input_frame({.cycle = static_cast<std::uint16_t>(good - 64)}), now));
  EXPECT_EQ(c.counters().old_cycle, 1U);
  // TransferStatus, truncated.
  EXPECT_TRUE(c.on_frame(input_frame({.cycle = static_cast<std::uint16_t>(good + 1), .transfer_status = 1}), now));
  EXPECT_EQ(c.counters().transfer_error, 1U);
  Bytes cut = input_frame({.cycle = static_cast<std::uint16_t>(good + 1)});
  cut.resize(20 + 30);
  EXPECT_TRUE(c.on_frame(cut, now));
  EXPECT_EQ(c.counters().truncated, 1U);
  // None of these moved the data or the watchdog.
  EXPECT_EQ(c.status().cycle_counter, good);
  EXPECT_EQ(c.next_deadline(), valid_at + kHold);
  // DataValid clear, Ignore, backup: new frames (the cycle counter moves on) but not taken.
  EXPECT_TRUE(next({.data_status = without(data_status::kDataValid), .drive_iops = 0}));
  EXPECT_EQ(c.counters().data_invalid, 1U);
  EXPECT_TRUE(c.on_frame(input_frame({.cycle = cycle}), now));  // the same counter again
  EXPECT_EQ(c.counters().repeated_cycle, 2U);
  EXPECT_EQ(c.next_deadline(), valid_at + kHold);  // invalid data does not feed the watchdog
  EXPECT_TRUE(next({.data_status = without(data_status::kStatePrimary)}));
  EXPECT_EQ(c.counters().backup, 1U);
  const core::TimePoint backup_at = now;
  EXPECT_EQ(c.next_deadline(), backup_at + kHold);  // the backup provider is alive
  EXPECT_TRUE(next({.data_status = static_cast<std::uint8_t>(data_status::kGood | data_status::kIgnore)}));
  EXPECT_EQ(c.counters().ignore, 1U);
  EXPECT_EQ(c.next_deadline(), backup_at + kHold);
  EXPECT_EQ(c.status().cycle_counter, good);
  EXPECT_EQ(c.iops(kDrive), iox_status::kGood);
  EXPECT_EQ(c.counters().frames, 1U);
  EXPECT_EQ(c.state(), RtConsumerState::Running);
}

TEST_F(PnRtConsumer, WatchdogFiresAtExactlyTheDataHoldTime) {
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(next());
  const core::TimePoint last = now;
  EXPECT_EQ(c.next_deadline(), last + kHold);
  EXPECT_FALSE(c.poll(last + kHold - nanoseconds(1)));
  EXPECT_EQ(c.state(), RtConsumerState::Running);
  EXPECT_TRUE(c.poll(last + kHold));
  EXPECT_EQ(c.state(), RtConsumerState::Timeout);
  EXPECT_EQ(c.counters().timeouts, 1U);
  EXPECT_EQ(c.reason(), "input frame 0x8002 silent for 6 ms (data hold time 6 ms); last valid cycle counter " +
                            std::to_string(cycle));
  EXPECT_FALSE(c.poll(last + kHold + kHold));  // an event once
  EXPECT_EQ(c.next_deadline(), core::TimePoint::max());
  // The device comes back: counted, not taken, until a new AR arms the consumer.
  now = last + kHold;
  EXPECT_TRUE(next());
  EXPECT_EQ(c.state(), RtConsumerState::Timeout);
  EXPECT_EQ(c.counters().inactive, 1U);
  EXPECT_EQ(c.counters().frames, 10U);
  c.arm(now);
  EXPECT_EQ(c.state(), RtConsumerState::Waiting);
  EXPECT_TRUE(c.reason().empty());
  EXPECT_FALSE(c.all_iops_good());  // the old AR's data is gone
  cycle = 5;  // a new AR may start anywhere
  ASSERT_TRUE(next());
  EXPECT_EQ(c.state(), RtConsumerState::Running);
  EXPECT_EQ(c.counters().frames, 11U);
}

TEST_F(PnRtConsumer, FrameAtTheDeadlineIsTooLate) {
  ASSERT_TRUE(next());
  now += kHold - kPeriod;
  EXPECT_TRUE(next());  // arrives exactly kHold after the last valid one
  EXPECT_EQ(c.state(), RtConsumerState::Timeout);
  EXPECT_EQ(c.counters().frames, 1U);
  EXPECT_EQ(c.counters().inactive, 1U);
}

TEST_F(PnRtConsumer, SilentDeviceAfterArmTimesOut) {
  EXPECT_EQ(c.next_deadline(), kArm + kHold);
  EXPECT_FALSE(c.poll(kArm + kHold - nanoseconds(1)));
  EXPECT_TRUE(c.poll(kArm + kHold));
  EXPECT_EQ(c.reason(), "no input frame 0x8002 from the device within the data hold time (6 ms)");
}

TEST_F(PnRtConsumer, DisarmedConsumerTakesNothing) {
  c.disarm();
  EXPECT_EQ(c.state(), RtConsumerState::Idle);
  EXPECT_EQ(c.next_deadline(), core::TimePoint::max());
  EXPECT_FALSE(c.poll(core::TimePoint{std::chrono::hours(5)}));
  EXPECT_TRUE(c.on_frame(input_frame({}), core::TimePoint{}));
  EXPECT_EQ(c.counters().inactive, 1U);
  EXPECT_EQ(to_string(RtConsumerState::Timeout), "data hold timeout");
}

}  // namespace
}  // namespace drivegate::profinet::test
