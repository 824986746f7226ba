// The engines on the device's side (RtSide::Device, the simulator): its provider sends the input
// CR from the device's MAC to the controller's, with the input data and the IOCS of the outputs,
// and the controller's consumer takes it; its consumer takes the controller's output CR and its
// watchdog names the output frame.
#include <gtest/gtest.h>

#include "tests/profinet_rt/rt_fixture.hpp"

namespace drivegate::profinet::test {
namespace {

using namespace std::chrono_literals;

TEST(PnRtDeviceSide, DeviceProviderFeedsTheControllerConsumer) {
  RtProvider device(iocr(kInputFrameId), RtSide::Device);
  RtConsumer controller(iocr(kInputFrameId));
  ASSERT_TRUE(device.ok());
  const std::array<std::uint8_t, 4> drive{0x02, 0x37, 0x00, 0x9E};
  std::copy(drive.begin(), drive.end(), device.data(kDrive).begin());
  EXPECT_EQ(device.data(kDrive).size(), 4U);
  EXPECT_EQ(device.data(kSensor).size(), 2U);
  for (const std::size_t i : {std::size_t{0}, kDrive, kSensor}) EXPECT_TRUE(device.set_iops(i, iox_status::kGood));
  EXPECT_FALSE(device.set_iocs(kSensor, iox_status::kGood));  // an input-only submodule has no IOCS here
  const core::TimePoint t0{1s};
  device.start(t0);
  controller.arm(t0);
  std::array<std::uint8_t, kMaxFrameSize> frame{};
  const std::size_t n = device.poll(t0 + 1ms, frame);
  ASSERT_GT(n, 0U);
  const EthernetView e = decode_ethernet(std::span<const std::uint8_t>(frame).first(n));
  EXPECT_EQ(e.header.src, kDevice);
  EXPECT_EQ(e.header.dst, kController);
  ASSERT_TRUE(controller.on_frame(std::span<const std::uint8_t>(frame).first(n), t0 + 1ms));
  EXPECT_EQ(controller.state(), RtConsumerState::Running);
  const auto got = controller.data(kDrive);
  EXPECT_EQ(Bytes(got.begin(), got.end()), Bytes(drive.begin(), drive.end()));
  EXPECT_TRUE(controller.all_iops_good());
  EXPECT_EQ(controller.iocs(kDrive), iox_status::kGood);
}

TEST(PnRtDeviceSide, DeviceConsumerTakesTheOutputCrAndTimesOut) {
  RtProvider controller(iocr(kOutputFrameId));
  RtConsumer device(iocr(kOutputFrameId), RtSide::Device);
  ASSERT_TRUE(device.ok());
  const std::array<std::uint8_t, 4> stw{0x04, 0x7F, 0x0A, 0xAB};
  std::copy(stw.begin(), stw.end(), controller.data(kDrive).begin());
  (void)controller.set_iops(kDrive, iox_status::kGood);
  const core::TimePoint t0{1s};
  controller.start(t0);
  device.arm(t0);
  std::array<std::uint8_t, kMaxFrameSize> frame{};
  const std::size_t n = controller.poll(t0 + 1ms, frame);
  ASSERT_TRUE(device.on_frame(std::span<const std::uint8_t>(frame).first(n), t0 + 1ms));
  const auto got = device.data(kDrive);
  EXPECT_EQ(Bytes(got.begin(), got.end()), Bytes(stw.begin(), stw.end()));
  EXPECT_EQ(device.iops(kDrive), iox_status::kGood);
  // The controller's frame from another MAC is not the controller's.
  RtConsumer other(iocr(kOutputFrameId), RtSide::Device);
  RtIocrConfig wrong = iocr(kOutputFrameId);
  wrong.controller_mac = {0x02, 0, 0, 0, 0, 9};
  RtProvider stranger(wrong);
  stranger.start(t0);
  other.arm(t0);
  const std::size_t m = stranger.poll(t0 + 1ms, frame);
  ASSERT_TRUE(other.on_frame(std::span<const std::uint8_t>(frame).first(m), t0 + 1ms));
  EXPECT_EQ(other.counters().wrong_source, 1U);
  // Silent for the data hold time (3 x 2 ms): the reason names the output frame.
  EXPECT_TRUE(device.poll(t0 + 7ms));
  EXPECT_EQ(device.reason(), "output frame 0x8001 silent for 6 ms (data hold time 6 ms); last valid cycle counter " +
                                 std::to_string(cycle_counter_at(static_cast<std::uint64_t>(core::to_ns(t0 + 1ms)))));
}

}  // namespace
}  // namespace drivegate::profinet::test
