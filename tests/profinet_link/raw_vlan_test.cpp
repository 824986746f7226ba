// RawSocketLink with PROFINET's rules over a veth pair: frames with and without an 802.1Q priority
// tag arrive as they were sent (the kernel takes the tag off; the link puts it back from
// PACKET_AUXDATA), frames of other EtherTypes behind a tag or without one are not handed up.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <vector>

#include "adapters/link/raw_socket_link.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "tests/profinet_link/frames.hpp"
#include "tests/profinet_link/veth.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet {
namespace {

using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using link::FrameView;
using test::make_frame;
using namespace std::chrono_literals;

class ProfinetRawLinkTest : public test::VethTest {
 protected:
  static std::unique_ptr<link::RawSocketLink> open_in(const NetNamespace& ns, const std::string& iface,
                                                      bool all_ethertypes = false, bool receive_ring = true) {
    link::RawSocketOptions o;
    o.interface = iface;
    o.all_ethertypes = all_ethertypes;
    o.receive_ring = receive_ring;
    auto l = std::make_unique<link::RawSocketLink>(kFrameRules, o);
    const NetnsScope in(ns);
    l->open();
    return l;
  }

  // Receives until `count` frames came or 2 s passed.
  static std::vector<std::vector<std::uint8_t>> receive(link::Link& l, std::size_t count) {
    std::vector<std::vector<std::uint8_t>> got;
    std::vector<link::FrameBuffer> in(16);
    const auto end = std::chrono::steady_clock::now() + 2s;
    while (got.size() < count && std::chrono::steady_clock::now() < end) {
      const std::size_t n = l.receive(in);
      for (std::size_t i = 0; i < n; ++i) got.push_back(test::bytes_of(in[i]));
      if (n == 0) test::wait_readable(l.wait_fd(), 50ms);
    }
    return got;
  }
};

TEST_F(ProfinetRawLinkTest, TaggedAndUntaggedFramesArriveAsSentOthersDoNot) {
  auto controller = open_in(*ns_a_, veth_->a());
  auto device = open_in(*ns_b_, veth_->b());
  const auto cyclic = make_frame(0x8001, true, 60, kPriorityRtCyclic);                // PCP 6, VID 0
  const auto alarm = make_frame(frame_id::kAlarmLow, true, 60, kPriorityAlarmLow);    // PCP 5
  const auto in_vlan = make_frame(0x8002, true, 60, kPriorityRtCyclic, 5);            // VID 5
  const auto dcp = make_frame(frame_id::kDcpIdentifyRequest, false, 60);              // untagged
  const auto longest = make_frame(0x8003, true, link::kMaxFrameBytes);                // 1518 with the tag
  const auto ipv4_tagged = make_frame(0x8004, true, 60, kPriorityRtCyclic, 0, 0x0800);
  const auto arp = make_frame(0x8005, false, 60, 0, 0, 0x0806);
  const std::array<FrameView, 7> frames{FrameView(cyclic), FrameView(ipv4_tagged), FrameView(alarm), FrameView(arp),
                                        FrameView(in_vlan), FrameView(dcp), FrameView(longest)};
  link::SendResult sent;
  {
    const drivegate::test::AllocationScope scope;
    sent = controller->send(frames);
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_EQ(sent.sent, 7U);

  std::vector<link::FrameBuffer> in(16);
  std::vector<std::vector<std::uint8_t>> got;
  {
    const auto end = std::chrono::steady_clock::now() + 2s;
    while (got.size() < 5 && std::chrono::steady_clock::now() < end) {
      std::size_t n = 0;
      {
        const drivegate::test::AllocationScope scope;
        n = device->receive(in);
        EXPECT_EQ(scope.count(), 0U);
      }
      for (std::size_t i = 0; i < n; ++i) got.push_back(test::bytes_of(in[i]));
      if (n == 0) test::wait_readable(device->wait_fd(), 50ms);
    }
  }
  ASSERT_EQ(got.size(), 5U);
  EXPECT_EQ(got[0], cyclic);
  EXPECT_EQ(got[1], alarm);
  EXPECT_EQ(got[2], in_vlan);
  EXPECT_EQ(got[3], dcp);
  EXPECT_EQ(got[4], longest);
  const EthernetView v = decode_ethernet(got[1]);
  ASSERT_TRUE(v.ok());
  EXPECT_TRUE(v.header.vlan);
  EXPECT_EQ(v.header.priority, kPriorityAlarmLow);
  EXPECT_EQ(v.frame_class, FrameClass::AlarmLow);
  EXPECT_FALSE(decode_ethernet(got[3]).header.vlan);
  // The kernel filter kept IPv4 and ARP away: nothing more is pending, nothing was counted.
  EXPECT_EQ(device->receive(in), 0U);
  EXPECT_EQ(device->counters().rx_frames, 5U);
  EXPECT_EQ(device->counters().rx_wrong_ethertype, 0U);
}

TEST_F(ProfinetRawLinkTest, TagsComeBackOnBothReceivePaths) {
  // The receive ring reads the tag from its slot header, recvmmsg from PACKET_AUXDATA: the same
  // frames come up either way.
  auto controller = open_in(*ns_a_, veth_->a());
  const auto cyclic = make_frame(0x8001, true, 60, kPriorityRtCyclic);
  const auto in_vlan = make_frame(0x8002, true, 60, kPriorityRtCyclic, 5);
  const auto dcp = make_frame(frame_id::kDcpIdentifyRequest, false, 60);
  const auto longest = make_frame(0x8003, true, link::kMaxFrameBytes);
  const auto ipv4_tagged = make_frame(0x8004, true, 60, kPriorityRtCyclic, 0, 0x0800);
  const std::array<FrameView, 5> frames{FrameView(cyclic), FrameView(ipv4_tagged), FrameView(in_vlan), FrameView(dcp),
                                        FrameView(longest)};
  for (const bool ring : {true, false}) {
    SCOPED_TRACE(ring ? "receive ring" : "recvmmsg");
    auto device = open_in(*ns_b_, veth_->b(), false, ring);
    EXPECT_EQ(device->receive_ring(), ring);
    EXPECT_EQ(controller->send(frames).sent, frames.size());
    const auto got = receive(*device, 4);
    ASSERT_EQ(got.size(), 4U);
    EXPECT_EQ(got[0], cyclic);
    EXPECT_EQ(got[1], in_vlan);
    EXPECT_EQ(got[2], dcp);
    EXPECT_EQ(got[3], longest);
    EXPECT_EQ(device->counters().rx_wrong_ethertype, 0U);
  }
}

TEST_F(ProfinetRawLinkTest, SendRefusesFramesTooLongForTheirTag) {
  auto controller = open_in(*ns_a_, veth_->a());
  const auto too_long_tagged = make_frame(0x8001, true, link::kMaxFrameBytes + 1);
  const auto too_long_untagged = make_frame(0x8001, false, link::kMaxUntaggedFrameBytes + 1);
  const auto too_short_tagged = make_frame(0x8001, true, 19);
  const std::array<FrameView, 3> frames{FrameView(too_long_tagged), FrameView(too_long_untagged),
                                        FrameView(too_short_tagged)};
  const link::SendResult r = controller->send(frames);
  EXPECT_EQ(r.invalid, 3U);
  EXPECT_EQ(controller->counters().tx_invalid, 3U);
}

TEST_F(ProfinetRawLinkTest, EveryEtherTypeModeCountsWhatItDrops) {
  // Without the kernel filter the link sees everything and counts what is not PROFINET; an
  // 802.1ad (88A8h) tag in front of 8892h is not PROFINET's either.
  auto controller = open_in(*ns_a_, veth_->a());
  auto device = open_in(*ns_b_, veth_->b(), true);
  const auto ipv4_tagged = make_frame(0x8004, true, 60, kPriorityRtCyclic, 0, 0x0800);
  auto qinq = make_frame(0x8001, true, 60);
  qinq[12] = 0x88;
  qinq[13] = 0xA8;
  const auto cyclic = make_frame(0x8001, true, 60);
  const std::array<FrameView, 3> frames{FrameView(ipv4_tagged), FrameView(qinq), FrameView(cyclic)};
  EXPECT_EQ(controller->send(frames).sent, 3U);
  const auto got = receive(*device, 1);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0], cyclic);
  EXPECT_EQ(device->counters().rx_wrong_ethertype, 2U);
}

TEST_F(ProfinetRawLinkTest, ErrorLinesSayProfinetAndDevices) {
  link::RawSocketOptions o;
  o.interface = "dgtnosuch0";
  link::RawSocketLink l(kFrameRules, o);
  const NetnsScope in(*ns_a_);
  try {
    l.open();
    FAIL() << "opened";
  } catch (const link::LinkError& e) {
    EXPECT_STREQ(e.what(), "profinet: no network interface 'dgtnosuch0'; give the name of the Ethernet port the devices are on");
  }
  EXPECT_EQ(open_in(*ns_a_, veth_->a())->describe(), "raw ethernet " + veth_->a() + " (AF_PACKET, EtherType 8892h)");
}

}  // namespace
}  // namespace drivegate::profinet
