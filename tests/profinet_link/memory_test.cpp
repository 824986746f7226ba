// PROFINET's frame rules, the shared MemoryLink with them, and the in-memory datagram pair.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "adapters/link/memory_datagram_port.hpp"
#include "adapters/link/memory_link.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "tests/profinet_link/frames.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet {
namespace {

using link::FrameCheck;
using link::Ipv4Endpoint;
using test::make_frame;

FrameCheck check(const std::vector<std::uint8_t>& f) { return link::check_frame(f, kFrameRules); }

TEST(ProfinetFrameRules, TaggedAndUntaggedByLengthAndInnerEtherType) {
  EXPECT_EQ(check(make_frame(0x8000, false, 16)), FrameCheck::Ok);  // header + FrameID
  EXPECT_EQ(check(make_frame(0x8000, false, 15)), FrameCheck::TooShort);
  EXPECT_EQ(check(make_frame(0x8000, true, 20)), FrameCheck::Ok);
  EXPECT_EQ(check(make_frame(0x8000, true, 19)), FrameCheck::TooShort);  // the tag leaves no FrameID
  EXPECT_EQ(check(make_frame(0x8000, false, 1514)), FrameCheck::Ok);
  EXPECT_EQ(check(make_frame(0x8000, false, 1515)), FrameCheck::TooLong);
  EXPECT_EQ(check(make_frame(0x8000, true, 1518)), FrameCheck::Ok);  // 1500 payload octets behind a tag
  EXPECT_EQ(check(make_frame(0x8000, true, 1519)), FrameCheck::TooLong);
  EXPECT_EQ(check(make_frame(0x8000, false, 60, 0, 0, 0x0800)), FrameCheck::WrongEtherType);
  EXPECT_EQ(check(make_frame(0x8000, true, 60, 6, 0, 0x0800)), FrameCheck::WrongEtherType);  // IPv4 behind a tag
  EXPECT_EQ(check(make_frame(0x8000, true, 60, 6, 0, 0x8100)), FrameCheck::WrongEtherType);  // two tags
  EXPECT_EQ(check(make_frame(0x8000, false, 60, 0, 0, 0x88A4)), FrameCheck::WrongEtherType);  // EtherCAT
}

TEST(ProfinetMemoryLink, HandsUpTaggedFramesAsSentAndDropsOtherInnerTypes) {
  link::MemoryLink controller(kFrameRules, 8);
  link::MemoryLink device(kFrameRules, 8);
  link::MemoryLink::connect(controller, device);
  controller.open();
  device.open();
  const auto cyclic = make_frame(0x8001, true, 60, kPriorityRtCyclic);
  const auto dcp = make_frame(frame_id::kDcpIdentifyRequest, false, 60);
  const auto ipv4 = make_frame(0x8001, true, 60, kPriorityRtCyclic, 0, 0x0800);
  const std::array<link::FrameView, 3> frames{link::FrameView(cyclic), link::FrameView(ipv4), link::FrameView(dcp)};
  EXPECT_EQ(controller.send(frames).sent, 3U);

  std::array<link::FrameBuffer, 4> in{};
  ASSERT_EQ(device.receive(in), 2U);
  EXPECT_EQ(test::bytes_of(in[0]), cyclic);
  EXPECT_EQ(test::bytes_of(in[1]), dcp);
  EXPECT_EQ(device.counters().rx_wrong_ethertype, 1U);
  const EthernetView v = decode_ethernet(in[0].view());
  ASSERT_TRUE(v.ok());
  EXPECT_TRUE(v.header.vlan);
  EXPECT_EQ(v.header.priority, kPriorityRtCyclic);
  EXPECT_EQ(v.header.frame_id, 0x8001);
}

constexpr Ipv4Endpoint kController{{10, 0, 0, 1}, 49152};
constexpr Ipv4Endpoint kDevice{{10, 0, 0, 2}, 34964};

TEST(MemoryDatagramPort, PairCarriesDatagramsWithTheirSource) {
  link::MemoryDatagramPort controller(kController, 4);
  link::MemoryDatagramPort device(kDevice, 4);
  link::MemoryDatagramPort::connect(controller, device);
  EXPECT_EQ(controller.send_to(kDevice, std::vector<std::uint8_t>{1, 2, 3}), link::DatagramStatus::Down);  // closed
  controller.open();
  device.open();
  EXPECT_EQ(controller.local(), kController);

  const std::vector<std::uint8_t> request{0x04, 0x00, 0x20, 0x00};
  link::Datagram in;
  {
    const drivegate::test::AllocationScope scope;
    EXPECT_EQ(controller.send_to(kDevice, request), link::DatagramStatus::Sent);
    ASSERT_TRUE(device.receive_from(in));
    EXPECT_EQ(device.send_to(in.from, in.view()), link::DatagramStatus::Sent);  // answer the source
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_EQ(in.from, kController);
  EXPECT_EQ(std::vector<std::uint8_t>(in.view().begin(), in.view().end()), request);
  ASSERT_TRUE(controller.receive_from(in));
  EXPECT_EQ(in.from, kDevice);
  EXPECT_FALSE(controller.receive_from(in));

  // Nobody at another address: sent, never arrives.
  EXPECT_EQ(controller.send_to(Ipv4Endpoint{{10, 0, 0, 3}, 34964}, request), link::DatagramStatus::Sent);
  EXPECT_EQ(device.pending(), 0U);
}

TEST(MemoryDatagramPort, RefusesBadSizesAndCountsOverflow) {
  link::MemoryDatagramPort controller(kController, 2);
  link::MemoryDatagramPort device(kDevice, 2);
  link::MemoryDatagramPort::connect(controller, device);
  controller.open();
  device.open();
  const std::vector<std::uint8_t> big(link::kMaxDatagramBytes + 1, 0x55);
  EXPECT_EQ(controller.send_to(kDevice, {}), link::DatagramStatus::Invalid);
  EXPECT_EQ(controller.send_to(kDevice, big), link::DatagramStatus::Invalid);
  EXPECT_FALSE(device.deliver(kController, big));
  const std::vector<std::uint8_t> one{1};
  for (int i = 0; i < 3; ++i) EXPECT_EQ(controller.send_to(kDevice, one), link::DatagramStatus::Sent);
  const link::DatagramCounters c = device.counters();
  EXPECT_EQ(c.rx_too_long, 1U);
  EXPECT_EQ(c.rx_overflow, 1U);
  EXPECT_EQ(device.pending(), 2U);
  EXPECT_EQ(controller.counters().tx_invalid, 2U);
  EXPECT_EQ(controller.counters().tx_datagrams, 3U);
}

}  // namespace
}  // namespace drivegate::profinet
