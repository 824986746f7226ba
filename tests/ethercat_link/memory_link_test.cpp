#include "adapters/ethercat/link/ethercat_link.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "tests/ethercat_link/frames.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::ethercat {
namespace {

using test::bytes_of;
using test::make_frame;

// Records what a MemoryLink sends and answers each frame with a copy whose first payload byte is
// incremented, the way a slave line hands a processed frame back.
class EchoSink final : public FrameSink {
 public:
  explicit EchoSink(MemoryLink& link) : link_(link) {}
  void on_frame(FrameView frame) noexcept override {
    if (record) seen.emplace_back(frame.begin(), frame.end());
    std::array<std::uint8_t, kMaxFrameSize> reply{};
    std::copy(frame.begin(), frame.end(), reply.begin());
    reply[16] = static_cast<std::uint8_t>(reply[16] + 1);
    link_.deliver({reply.data(), frame.size()});
  }
  std::vector<std::vector<std::uint8_t>> seen;
  bool record = true;

 private:
  MemoryLink& link_;
};

TEST(FrameCheck, LengthAndEtherType) {
  // Lengths from IEEE 802.3 (14-byte header, 1500-byte payload) and the 2-byte EtherCAT header.
  EXPECT_EQ(check_frame(make_frame(0, 16)), FrameCheck::Ok);
  EXPECT_EQ(check_frame(make_frame(0, 15)), FrameCheck::TooShort);
  EXPECT_EQ(check_frame(make_frame(0, 0)), FrameCheck::TooShort);
  EXPECT_EQ(check_frame(make_frame(0, 1514)), FrameCheck::Ok);
  EXPECT_EQ(check_frame(make_frame(0, 1515)), FrameCheck::TooLong);
  EXPECT_EQ(check_frame(make_frame(0, 60, 0x0800)), FrameCheck::WrongEtherType);
  EXPECT_EQ(check_frame(make_frame(0, 60, 0x8100)), FrameCheck::WrongEtherType);  // VLAN-tagged
  EXPECT_EQ(check_frame(make_frame(0, 60, 0xA488)), FrameCheck::WrongEtherType);  // byte order swapped
  const std::vector<std::uint8_t> exact = {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0, 0, 0, 0, 1, 0x88, 0xA4, 0x00, 0x10};
  EXPECT_EQ(check_frame(exact), FrameCheck::Ok);
}

TEST(MemoryLink, SinkSeesFramesInOrderAndRepliesQueueForReceive) {
  MemoryLink link(8);
  EchoSink sink(link);
  link.set_sink(&sink);
  link.open();
  EXPECT_EQ(link.state(), LinkState::Up);

  const auto a = make_frame(0x10);
  const auto b = make_frame(0x20, 100);
  const std::array<FrameView, 2> frames{FrameView(a), FrameView(b)};
  const SendResult r = link.send(frames);
  EXPECT_EQ(r.sent, 2U);
  EXPECT_EQ(r.status, SendStatus::Sent);
  ASSERT_EQ(sink.seen.size(), 2U);
  EXPECT_EQ(sink.seen[0], a);
  EXPECT_EQ(sink.seen[1], b);

  std::array<FrameBuffer, 4> out{};
  ASSERT_EQ(link.receive(out), 2U);
  auto want = a;
  want[16] = 0x11;
  EXPECT_EQ(bytes_of(out[0]), want);
  want = b;
  want[16] = 0x21;
  EXPECT_EQ(bytes_of(out[1]), want);
  EXPECT_EQ(link.receive(out), 0U);

  const LinkCounters c = link.counters();
  EXPECT_EQ(c.tx_frames, 2U);
  EXPECT_EQ(c.rx_frames, 2U);
}

TEST(MemoryLink, ConnectedPairCarriesBothWays) {
  MemoryLink master(4);
  MemoryLink slave(4);
  MemoryLink::connect(master, slave);
  master.open();
  slave.open();
  const auto f = make_frame(1);
  EXPECT_EQ(master.send(FrameView(f)).sent, 1U);
  std::array<FrameBuffer, 2> out{};
  ASSERT_EQ(slave.receive(out), 1U);
  EXPECT_EQ(bytes_of(out[0]), f);
  const auto g = make_frame(2, 200);
  EXPECT_EQ(slave.send(FrameView(g)).sent, 1U);
  ASSERT_EQ(master.receive(out), 1U);
  EXPECT_EQ(bytes_of(out[0]), g);
  EXPECT_EQ(master.receive(out), 0U);  // own frames are not seen back
}

TEST(MemoryLink, ReceiveTakesOnlyWhatFitsAndKeepsTheRestInOrder) {
  MemoryLink link(8);
  link.open();
  for (std::uint8_t i = 0; i < 5; ++i) ASSERT_TRUE(link.deliver(make_frame(i)));
  std::array<FrameBuffer, 2> out{};
  ASSERT_EQ(link.receive(out), 2U);
  EXPECT_EQ(out[0].bytes[16], 0);
  EXPECT_EQ(out[1].bytes[16], 1);
  std::array<FrameBuffer, 8> rest{};
  ASSERT_EQ(link.receive(rest), 3U);
  EXPECT_EQ(rest[0].bytes[16], 2);
  EXPECT_EQ(rest[2].bytes[16], 4);
}

TEST(MemoryLink, FullQueueDropsAndCounts) {
  MemoryLink link(3);
  link.open();
  for (std::uint8_t i = 0; i < 3; ++i) EXPECT_TRUE(link.deliver(make_frame(i)));
  EXPECT_FALSE(link.deliver(make_frame(3)));
  EXPECT_FALSE(link.deliver(make_frame(4)));
  EXPECT_EQ(link.counters().rx_overflow, 2U);
  std::array<FrameBuffer, 8> out{};
  ASSERT_EQ(link.receive(out), 3U);
  EXPECT_EQ(out[2].bytes[16], 2);  // the oldest stay, the newest were dropped
  // Room again: the ring wraps.
  for (std::uint8_t i = 10; i < 13; ++i) EXPECT_TRUE(link.deliver(make_frame(i)));
  ASSERT_EQ(link.receive(out), 3U);
  EXPECT_EQ(out[0].bytes[16], 10);
  EXPECT_EQ(out[2].bytes[16], 12);
}

TEST(MemoryLink, BadFramesAreDroppedAndCountedByKind) {
  MemoryLink link(8);
  link.open();
  EXPECT_FALSE(link.deliver(make_frame(0, 15)));
  EXPECT_FALSE(link.deliver(make_frame(0, 1515)));
  EXPECT_FALSE(link.deliver(make_frame(0, 60, 0x0800)));
  EXPECT_FALSE(link.deliver(make_frame(0, 60, 0x8892)));  // PROFINET
  std::array<FrameBuffer, 4> out{};
  EXPECT_EQ(link.receive(out), 0U);
  const LinkCounters c = link.counters();
  EXPECT_EQ(c.rx_too_short, 1U);
  EXPECT_EQ(c.rx_too_long, 1U);
  EXPECT_EQ(c.rx_wrong_ethertype, 2U);
  EXPECT_EQ(c.rx_frames, 0U);
}

TEST(MemoryLink, InvalidFramesAreSkippedOnSendAndTheRestGo) {
  MemoryLink link(8);
  EchoSink sink(link);
  link.set_sink(&sink);
  link.open();
  const auto ok1 = make_frame(1);
  const auto shorty = make_frame(2, 10);
  const auto longy = make_frame(3, 1600);
  const auto ok2 = make_frame(4);
  const std::array<FrameView, 4> frames{FrameView(ok1), FrameView(shorty), FrameView(longy), FrameView(ok2)};
  const SendResult r = link.send(frames);
  EXPECT_EQ(r.sent, 2U);
  EXPECT_EQ(r.invalid, 2U);
  EXPECT_EQ(r.unsent, 0U);
  EXPECT_EQ(r.status, SendStatus::Sent);
  ASSERT_EQ(sink.seen.size(), 2U);
  EXPECT_EQ(sink.seen[1], ok2);
  EXPECT_EQ(link.counters().tx_invalid, 2U);
}

TEST(MemoryLink, WireDownRefusesAndCountsTransitions) {
  MemoryLink master(4);
  MemoryLink slave(4);
  MemoryLink::connect(master, slave);
  master.open();
  slave.open();
  master.set_wire_state(LinkState::NoCarrier);
  EXPECT_EQ(master.poll_state(core::TimePoint{}), LinkState::NoCarrier);
  const auto f = make_frame(1);
  const std::array<FrameView, 2> two{FrameView(f), FrameView(f)};
  const SendResult r = master.send(two);
  EXPECT_EQ(r.sent, 0U);
  EXPECT_EQ(r.unsent, 2U);
  EXPECT_EQ(r.status, SendStatus::Down);
  EXPECT_EQ(master.counters().tx_down, 2U);
  EXPECT_EQ(slave.pending(), 0U);
  // A cut wire delivers nothing either.
  EXPECT_FALSE(master.deliver(FrameView(f)));

  master.set_wire_state(LinkState::Up);
  EXPECT_EQ(master.send(FrameView(f)).sent, 1U);
  EXPECT_EQ(slave.pending(), 1U);
  const LinkCounters c = master.counters();
  EXPECT_EQ(c.link_downs, 1U);
  EXPECT_EQ(c.link_ups, 1U);
}

TEST(MemoryLink, ClosedLinkSendsNothingAndSaysClosed) {
  MemoryLink link(4);
  EXPECT_EQ(link.state(), LinkState::Closed);
  const auto f = make_frame(1);
  EXPECT_EQ(link.send(FrameView(f)).status, SendStatus::Down);
  EXPECT_FALSE(link.deliver(FrameView(f)));
  link.open();
  EXPECT_TRUE(link.deliver(FrameView(f)));
  link.close();
  EXPECT_EQ(link.state(), LinkState::Closed);
  link.open();
  EXPECT_EQ(link.pending(), 0U);  // close() dropped what was queued
}

TEST(MemoryLink, DestroyedPeerIsDetached) {
  MemoryLink master(4);
  master.open();
  {
    MemoryLink slave(4);
    MemoryLink::connect(master, slave);
  }
  const auto f = make_frame(1);
  EXPECT_EQ(master.send(FrameView(f)).sent, 1U);  // goes nowhere, and touches no freed peer
}

TEST(MemoryLink, CyclicCallsDoNotAllocate) {
  MemoryLink link(64);
  EchoSink sink(link);
  sink.record = false;  // recording would allocate in the sink, not in the link
  link.set_sink(&sink);
  link.open();
  const auto f = make_frame(1, 300);
  const std::array<FrameView, 4> frames{FrameView(f), FrameView(f), FrameView(f), FrameView(f)};
  std::array<FrameBuffer, 8> out{};
  std::size_t received = 0;
  const drivegate::test::AllocationScope scope;
  for (int cycle = 0; cycle < 100; ++cycle) {
    (void)link.send(frames);
    received += link.receive(out);
    (void)link.poll_state(core::TimePoint{});
    (void)link.counters();
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(received, 400U);
}

}  // namespace
}  // namespace drivegate::ethercat
