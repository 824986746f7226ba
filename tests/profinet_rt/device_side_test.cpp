// The same engines on the simulated device's side (RtRole::Device): the device provides the input
// CR and consumes the output CR. Controller and device exchange both CRs over a cable of two
// link::MemoryLinks for 100 periods: the controller's outputs with their IOPS arrive at the
// device, the device's inputs, IOPS and its IOCS of our outputs arrive at the controller.
#include <gtest/gtest.h>

#include "adapters/link/memory_link.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "tests/profinet_rt/rt_fixture.hpp"

namespace drivegate::profinet::test {
namespace {

RtIocrConfig device_side(std::uint16_t frame) {
  RtIocrConfig c = iocr(frame);
  c.role = RtRole::Device;
  return c;
}

// Sends whatever the provider has due on `from`, then hands what `to` received to the consumer.
void carry(RtProvider& p, link::MemoryLink& from, link::MemoryLink& to, RtConsumer& c, core::TimePoint now) {
  std::array<std::uint8_t, kMaxFrameSize> out{};
  if (const std::size_t n = p.poll(now, out)) {
    ASSERT_EQ(from.send(std::span<const std::uint8_t>(out).first(n)).sent, 1U);
  }
  std::array<link::FrameBuffer, 4> in{};
  const std::size_t got = to.receive(in);
  for (std::size_t i = 0; i < got; ++i) EXPECT_TRUE(c.on_frame(in[i].view(), now));
}

TEST(PnRt, DeviceSideRoundTrip) {
  link::MemoryLink controller_link(kFrameRules, 8);
  link::MemoryLink device_link(kFrameRules, 8);
  link::MemoryLink::connect(controller_link, device_link);
  controller_link.open();
  device_link.open();

  RtProvider outputs(iocr(kOutputFrameId));          // controller → device
  RtConsumer inputs(iocr(kInputFrameId));            // device → controller
  RtProvider device_inputs(device_side(kInputFrameId));
  RtConsumer device_outputs(device_side(kOutputFrameId));
  ASSERT_TRUE(outputs.ok() && inputs.ok() && device_inputs.ok() && device_outputs.ok());
  EXPECT_EQ(device_inputs.frame_size(), outputs.frame_size());  // both C_SDUs padded to 40

  const std::array<std::uint8_t, 4> stw{0x04, 0x7F, 0x40, 0x00};
  std::copy(stw.begin(), stw.end(), outputs.data(kDrive).begin());
  EXPECT_TRUE(outputs.set_iops(kDrive, iox_status::kGood));
  EXPECT_TRUE(outputs.set_iocs(kSensor, iox_status::kGood));
  EXPECT_FALSE(outputs.set_iops(kSensor, iox_status::kGood));  // no outputs: no IOPS in this CR
  const std::array<std::uint8_t, 4> zsw{0x0B, 0x37, 0x12, 0x34};
  std::copy(zsw.begin(), zsw.end(), device_inputs.data(kDrive).begin());
  device_inputs.data(kSensor)[0] = 0xAB;
  device_inputs.data(kSensor)[1] = 0xCD;
  for (const std::size_t i : {std::size_t{0}, kDrive, kSensor}) EXPECT_TRUE(device_inputs.set_iops(i, iox_status::kGood));
  EXPECT_TRUE(device_inputs.set_iocs(kDrive, iox_status::kGood));  // the device's IOCS of our outputs

  core::TimePoint now{std::chrono::seconds(3)};
  outputs.start(now);
  const core::TimePoint start = now + outputs.period() / 2;  // phase 2: one send clock in
  device_inputs.start(now);
  inputs.arm(now);
  device_outputs.arm(now);
  for (int n = 0; n < 100; ++n) {
    now = std::min(outputs.next_deadline(), device_inputs.next_deadline());
    carry(outputs, controller_link, device_link, device_outputs, now);
    carry(device_inputs, device_link, controller_link, inputs, now);
    EXPECT_FALSE(inputs.poll(now));
    EXPECT_FALSE(device_outputs.poll(now));
  }

  EXPECT_EQ(device_outputs.state(), RtConsumerState::Running);
  EXPECT_EQ(inputs.state(), RtConsumerState::Running);
  ASSERT_EQ(device_outputs.data(kDrive).size(), stw.size());
  EXPECT_TRUE(std::equal(stw.begin(), stw.end(), device_outputs.data(kDrive).begin()));
  EXPECT_EQ(device_outputs.iops(kDrive), iox_status::kGood);
  EXPECT_EQ(device_outputs.iocs(kSensor), iox_status::kGood);
  EXPECT_TRUE(device_outputs.provider_run());
  ASSERT_EQ(inputs.data(kDrive).size(), zsw.size());
  EXPECT_TRUE(std::equal(zsw.begin(), zsw.end(), inputs.data(kDrive).begin()));
  EXPECT_EQ(inputs.data(kSensor)[0], 0xAB);
  EXPECT_EQ(inputs.data(kSensor)[1], 0xCD);
  EXPECT_TRUE(inputs.all_iops_good());
  EXPECT_EQ(inputs.iocs(kDrive), iox_status::kGood);
  // 100 periods of 2 ms (both CRs at phase 2): every frame taken on both sides.
  EXPECT_EQ(now - start, 99 * outputs.period());
  EXPECT_EQ(device_outputs.counters().frames, 100U);
  EXPECT_EQ(inputs.counters().frames, 100U);
  EXPECT_EQ(device_outputs.counters().wrong_source + inputs.counters().wrong_source, 0U);
  EXPECT_EQ(device_outputs.counters().repeated_cycle + inputs.counters().repeated_cycle, 0U);

  // The device's frames go from its MAC to the controller's, tagged with priority 6.
  std::array<std::uint8_t, kMaxFrameSize> out{};
  const std::size_t len = device_inputs.poll(device_inputs.next_deadline(), out);
  const EthernetView e = decode_ethernet(std::span<const std::uint8_t>(out).first(len));
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e.header.src, kDevice);
  EXPECT_EQ(e.header.dst, kController);
  EXPECT_EQ(e.header.frame_id, kInputFrameId);
  EXPECT_EQ(e.header.priority, kPriorityRtCyclic);
}

}  // namespace
}  // namespace drivegate::profinet::test
