// RawSocketLink over a veth pair whose ends sit in two network namespaces the test creates (and
// always removes): end A is the master's port, end B stands for the first slave.
#include "adapters/ethercat/link/ethercat_link.hpp"

#include <arpa/inet.h>
#include <linux/capability.h>
#include <linux/if_ether.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstring>
#include <memory>
#include <vector>

#include "tests/ethercat_link/frames.hpp"
#include "tests/support/alloc_counter.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::ethercat {
namespace {

using drivegate::test::ChildProcess;
using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using drivegate::test::VethPair;
using test::bytes_of;
using test::make_frame;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

core::TimePoint now() { return std::chrono::time_point_cast<core::Duration>(Clock::now()); }

// Waits until `fd` is readable (or reports an error), at most `timeout`.
bool wait_readable(int fd, std::chrono::milliseconds timeout) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, static_cast<int>(timeout.count())) > 0;
}

// Receives until `count` frames came or `timeout` passed, waiting on the link's fd in between.
std::vector<std::vector<std::uint8_t>> receive_frames(Link& link, std::size_t count, std::chrono::milliseconds timeout) {
  std::vector<std::vector<std::uint8_t>> got;
  std::vector<FrameBuffer> out(256);
  const auto end = Clock::now() + timeout;
  while (got.size() < count) {
    const std::size_t n = link.receive(out);
    for (std::size_t i = 0; i < n; ++i) got.push_back(bytes_of(out[i]));
    if (n > 0) continue;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now());
    if (left <= 0ms || !wait_readable(link.wait_fd(), left)) break;
  }
  return got;
}

// poll_state() until it says `want`, at most `timeout`; the fd wait paces the checks (it wakes at
// once on the POLLERR a downed interface raises).
bool wait_state(Link& link, LinkState want, std::chrono::milliseconds timeout) {
  for (const auto end = Clock::now() + timeout;;) {
    if (link.poll_state(now()) == want) return true;
    if (Clock::now() >= end) return false;
    pollfd p{link.wait_fd(), 0, 0};
    ::poll(&p, 1, 2);
  }
}

// Sends raw bytes on `iface` from the current namespace with a plain packet socket, for frames
// RawSocketLink itself refuses to send (too short, too long).
void raw_send(const std::string& iface, const std::vector<std::uint8_t>& frame) {
  const int fd = ::socket(AF_PACKET, SOCK_RAW, 0);
  ASSERT_GE(fd, 0);
  sockaddr_ll to{};
  to.sll_family = AF_PACKET;
  to.sll_ifindex = static_cast<int>(::if_nametoindex(iface.c_str()));
  to.sll_halen = 6;
  ASSERT_EQ(::sendto(fd, frame.data(), frame.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to),
            static_cast<ssize_t>(frame.size()))
      << std::strerror(errno);
  ::close(fd);
}

class RawSocketLinkTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_a_ = std::make_unique<NetNamespace>();
    ns_b_ = std::make_unique<NetNamespace>();
    veth_ = std::make_unique<VethPair>(ns_a_.get(), ns_b_.get());
  }

  // A link on end A (or B) opened inside its namespace; the socket stays there.
  std::unique_ptr<RawSocketLink> open_a(RawSocketOptions o = {}) { return open_in(*ns_a_, veth_->a(), std::move(o)); }
  std::unique_ptr<RawSocketLink> open_b(RawSocketOptions o = {}) { return open_in(*ns_b_, veth_->b(), std::move(o)); }
  static std::unique_ptr<RawSocketLink> open_in(const NetNamespace& ns, const std::string& iface, RawSocketOptions o) {
    o.interface = iface;
    o.state_interval = core::Duration{0};  // tests ask the kernel on every poll_state()
    auto link = std::make_unique<RawSocketLink>(std::move(o));
    const NetnsScope in(ns);
    link->open();
    return link;
  }
  // open() on `iface` inside `ns`; the LinkError text, or "" when it opened.
  static std::string open_error(const NetNamespace& ns, const std::string& iface) {
    RawSocketOptions o;
    o.interface = iface;
    RawSocketLink link(o);
    const NetnsScope in(ns);
    try {
      link.open();
    } catch (const LinkError& e) {
      return e.what();
    }
    return {};
  }

  // Members go in reverse order: the pair before its namespaces.
  std::unique_ptr<NetNamespace> ns_a_;
  std::unique_ptr<NetNamespace> ns_b_;
  std::unique_ptr<VethPair> veth_;
};

TEST_F(RawSocketLinkTest, FrameSentOnOneEndArrivesOnTheOther) {
  auto a = open_a();
  auto b = open_b();
  EXPECT_EQ(a->state(), LinkState::Up);
  EXPECT_EQ(b->state(), LinkState::Up);

  const auto f = make_frame(0x42, 60);
  const SendResult r = a->send(FrameView(f));
  EXPECT_EQ(r.sent, 1U);
  EXPECT_EQ(r.status, SendStatus::Sent);
  const auto got = receive_frames(*b, 1, 2000ms);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0], f);  // byte for byte, no padding, no FCS

  // And the other way, with the largest frame there is.
  const auto big = make_frame(0x07, kMaxFrameSize);
  EXPECT_EQ(b->send(FrameView(big)).sent, 1U);
  const auto back = receive_frames(*a, 1, 2000ms);
  ASSERT_EQ(back.size(), 1U);
  EXPECT_EQ(back[0], big);
  EXPECT_EQ(a->counters().tx_frames, 1U);
  EXPECT_EQ(a->counters().rx_frames, 1U);
}

TEST_F(RawSocketLinkTest, OwnFramesAreNotReadBack) {
  // The kernel shows outgoing frames only to sockets that take every EtherType; one bound to 88A4h
  // never sees them, one bound to all sees none either with PACKET_IGNORE_OUTGOING.
  RawSocketOptions all;
  all.all_ethertypes = true;
  auto a = open_a();
  auto a_all = open_a(all);
  auto b = open_b();
  EXPECT_TRUE(a_all->ignores_outgoing());  // Linux 4.20+
  const auto f = make_frame(1);
  ASSERT_EQ(a->send(FrameView(f)).sent, 1U);
  ASSERT_EQ(a_all->send(FrameView(f)).sent, 1U);
  ASSERT_EQ(receive_frames(*b, 2, 2000ms).size(), 2U);  // they went out
  std::array<FrameBuffer, 4> out{};
  EXPECT_EQ(a->receive(out), 0U);
  EXPECT_EQ(a_all->receive(out), 0U);
  // a_all would see a's frame leave (another socket's outgoing frame) but for the option.
  EXPECT_EQ(a_all->counters().rx_own, 0U);
  EXPECT_EQ(a->counters().rx_own, 0U);
}

TEST_F(RawSocketLinkTest, WithoutIgnoreOutgoingOutgoingFramesAreDroppedAndCounted) {
  // The kernel never shows a packet socket its own frames (skb_loop_sk), but it shows a socket that
  // takes every EtherType the frames other sockets send out of the port. Without
  // PACKET_IGNORE_OUTGOING (kernels before 4.20) those arrive marked PACKET_OUTGOING.
  RawSocketOptions o;
  o.all_ethertypes = true;
  o.ignore_outgoing = false;
  auto a = open_a(o);
  auto other = open_a();  // another sender on the same port
  auto b = open_b();
  EXPECT_FALSE(a->ignores_outgoing());
  const auto f = make_frame(1);
  const std::array<FrameView, 3> three{FrameView(f), FrameView(f), FrameView(f)};
  ASSERT_EQ(other->send(three).sent, 3U);
  ASSERT_EQ(a->send(FrameView(f)).sent, 1U);
  ASSERT_EQ(receive_frames(*b, 4, 2000ms).size(), 4U);
  // The copies of outgoing frames are queued when they leave, before the peer can see them.
  std::array<FrameBuffer, 8> out{};
  EXPECT_EQ(a->receive(out), 0U);
  EXPECT_EQ(a->counters().rx_own, 3U);
  EXPECT_EQ(a->counters().rx_frames, 0U);
  // A frame from the peer still comes through.
  const auto g = make_frame(9);
  ASSERT_EQ(b->send(FrameView(g)).sent, 1U);
  const auto got = receive_frames(*a, 1, 2000ms);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0], g);
}

TEST_F(RawSocketLinkTest, OtherEtherTypesAreNotDeliveredOrAreCounted) {
  auto a = open_a();
  auto b = open_b();
  RawSocketOptions all;
  all.all_ethertypes = true;
  auto b_all = open_b(all);
  // The link sends what it is given; the receiving socket is bound to 88A4h only.
  const auto ip = make_frame(1, 60, 0x0800);
  const auto profinet = make_frame(2, 60, 0x8892);
  const auto ecat = make_frame(3, 60);
  const std::array<FrameView, 3> frames{FrameView(ip), FrameView(profinet), FrameView(ecat)};
  ASSERT_EQ(a->send(frames).sent, 3U);
  // veth keeps the order: once the EtherCAT frame is here, the others had their chance.
  const auto got = receive_frames(*b, 1, 2000ms);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0], ecat);
  std::array<FrameBuffer, 4> out{};
  EXPECT_EQ(b->receive(out), 0U);
  EXPECT_EQ(b->counters().rx_frames, 1U);
  EXPECT_EQ(b->counters().rx_wrong_ethertype, 0U);  // the kernel never gave them to it
  // The socket that takes every EtherType drops and counts them.
  const auto got_all = receive_frames(*b_all, 1, 2000ms);
  ASSERT_EQ(got_all.size(), 1U);
  EXPECT_EQ(got_all[0], ecat);
  EXPECT_EQ(b_all->counters().rx_wrong_ethertype, 2U);
}

TEST_F(RawSocketLinkTest, TooShortAndTooLongFramesAreDroppedAndCounted) {
  auto b = open_b();
  // Jumbo frames need a larger MTU on both ends; without it the sender could not send them.
  veth_->set(VethPair::End::A, {"mtu", "2000"});
  veth_->set(VethPair::End::B, {"mtu", "2000"});
  {
    const NetnsScope in(*ns_a_);
    raw_send(veth_->a(), make_frame(1, 15));    // an Ethernet header and one byte
    raw_send(veth_->a(), make_frame(2, 1600));  // 86 bytes over the largest standard frame
    raw_send(veth_->a(), make_frame(3, 60));
  }
  const auto got = receive_frames(*b, 1, 2000ms);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0], make_frame(3, 60));
  const LinkCounters c = b->counters();
  EXPECT_EQ(c.rx_too_short, 1U);
  EXPECT_EQ(c.rx_too_long, 1U);
  EXPECT_EQ(c.rx_frames, 1U);
}

TEST_F(RawSocketLinkTest, RingAndSystemCallPathsDeliverAndDropAlike) {
  // The receive ring by default (this kernel has it), recvmmsg when asked; both deliver the same
  // frames and drop the same ones, including a frame longer than a ring slot (the kernel cuts it).
  veth_->set(VethPair::End::A, {"mtu", "2000"});
  veth_->set(VethPair::End::B, {"mtu", "2000"});
  for (const bool ring : {true, false}) {
    SCOPED_TRACE(ring ? "receive ring" : "recvmmsg");
    RawSocketOptions o;
    o.receive_ring = ring;
    auto b = open_b(o);
    EXPECT_EQ(b->receive_ring(), ring);
    {
      const NetnsScope in(*ns_a_);
      raw_send(veth_->a(), make_frame(1, 15));
      raw_send(veth_->a(), make_frame(2, 1600));
      raw_send(veth_->a(), make_frame(3, 1999));  // beyond a 2048-byte ring slot with its header
      raw_send(veth_->a(), make_frame(4, 60));
      raw_send(veth_->a(), make_frame(5, kMaxFrameSize));
    }
    const auto got = receive_frames(*b, 2, 2000ms);
    ASSERT_EQ(got.size(), 2U);
    EXPECT_EQ(got[0], make_frame(4, 60));
    EXPECT_EQ(got[1], make_frame(5, kMaxFrameSize));
    const LinkCounters c = b->counters();
    EXPECT_EQ(c.rx_too_short, 1U);
    EXPECT_EQ(c.rx_too_long, 2U);
    EXPECT_EQ(c.rx_frames, 2U);
  }
}

TEST_F(RawSocketLinkTest, ReceiveRingWrapsAroundAndKeepsOrder) {
  // More frames than the ring has slots (a 64 KiB ring: 32 slots), read as they come: the slots
  // are handed back and reused in order.
  RawSocketOptions o;
  o.receive_buffer_bytes = 1 << 16;
  auto a = open_a();
  auto b = open_b(o);
  ASSERT_TRUE(b->receive_ring());
  for (int round = 0; round < 20; ++round) {
    std::vector<std::vector<std::uint8_t>> sent;
    std::vector<FrameView> views;
    for (std::size_t k = 0; k < 5; ++k) sent.push_back(make_frame(static_cast<std::uint8_t>(round * 5 + static_cast<int>(k)), 60 + k));
    for (const auto& f : sent) views.emplace_back(f);
    ASSERT_EQ(a->send(views).sent, sent.size());
    const auto got = receive_frames(*b, sent.size(), 2000ms);
    ASSERT_EQ(got, sent) << "round " << round;
  }
  EXPECT_EQ(b->counters().rx_frames, 100U);
  EXPECT_EQ(b->counters().rx_overflow, 0U);
}

TEST_F(RawSocketLinkTest, InvalidFramesAreRefusedOnSendAndTheRestGo) {
  auto a = open_a();
  auto b = open_b();
  const auto ok = make_frame(1);
  const auto shorty = make_frame(2, 12);
  const auto longy = make_frame(3, kMaxFrameSize + 1);
  const std::array<FrameView, 4> frames{FrameView(shorty), FrameView(ok), FrameView(longy), FrameView(ok)};
  const SendResult r = a->send(frames);
  EXPECT_EQ(r.sent, 2U);
  EXPECT_EQ(r.invalid, 2U);
  EXPECT_EQ(r.status, SendStatus::Sent);
  EXPECT_EQ(receive_frames(*b, 2, 2000ms).size(), 2U);
  EXPECT_EQ(a->counters().tx_invalid, 2U);
}

TEST_F(RawSocketLinkTest, BatchOf64FramesInOneCallArrivesInOrder) {
  auto a = open_a();
  auto b = open_b();
  std::vector<std::vector<std::uint8_t>> frames;
  for (std::size_t i = 0; i < 64; ++i) frames.push_back(make_frame(static_cast<std::uint8_t>(i), 60 + i * 20));
  std::vector<FrameView> views(frames.begin(), frames.end());
  const SendResult r = a->send(views);
  EXPECT_EQ(r.sent, 64U);
  EXPECT_EQ(r.status, SendStatus::Sent);
  const auto got = receive_frames(*b, 64, 3000ms);
  ASSERT_EQ(got.size(), 64U);
  for (std::size_t i = 0; i < 64; ++i) EXPECT_EQ(got[i], frames[i]) << "frame " << i;
  EXPECT_EQ(b->counters().rx_overflow, 0U);
}

TEST_F(RawSocketLinkTest, BatchLargerThanOneSystemCallIsSplit) {
  auto a = open_a();
  auto b = open_b();
  std::vector<std::vector<std::uint8_t>> frames;
  for (std::size_t i = 0; i < 3 * kLinkBatch + 5; ++i) frames.push_back(make_frame(static_cast<std::uint8_t>(i), 100));
  std::vector<FrameView> views(frames.begin(), frames.end());
  EXPECT_EQ(a->send(views).sent, frames.size());
  const auto got = receive_frames(*b, frames.size(), 3000ms);
  ASSERT_EQ(got.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) EXPECT_EQ(got[i], frames[i]) << "frame " << i;
}

TEST_F(RawSocketLinkTest, PeerDownIsNoCarrierAndTheLinkRecovers) {
  auto a = open_a();
  auto b = open_b();
  veth_->set_up(VethPair::End::B, false);  // the first slave powered off, the cable pulled
  ASSERT_TRUE(wait_state(*a, LinkState::NoCarrier, 2000ms)) << to_string(a->state());
  EXPECT_EQ(a->counters().link_downs, 1U);

  veth_->set_up(VethPair::End::B, true);
  veth_->wait_up();
  ASSERT_TRUE(wait_state(*a, LinkState::Up, 2000ms)) << to_string(a->state());
  EXPECT_EQ(a->counters().link_ups, 1U);
  ASSERT_TRUE(wait_state(*b, LinkState::Up, 2000ms));
  const auto f = make_frame(5);
  EXPECT_EQ(a->send(FrameView(f)).sent, 1U);
  const auto got = receive_frames(*b, 1, 2000ms);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0], f);
}

TEST_F(RawSocketLinkTest, OwnEndDownIsReportedBySendAndStateAndRecovers) {
  auto a = open_a();
  auto b = open_b();
  veth_->set_up(VethPair::End::A, false);
  const auto f = make_frame(5);
  const std::array<FrameView, 2> two{FrameView(f), FrameView(f)};
  const SendResult r = a->send(two);
  EXPECT_EQ(r.sent, 0U);
  EXPECT_EQ(r.unsent, 2U);
  EXPECT_EQ(r.status, SendStatus::Down);
  EXPECT_EQ(a->counters().tx_down, 2U);
  // The ENETDOWN makes the next poll_state() ask at once, whatever the interval.
  EXPECT_EQ(a->poll_state(now()), LinkState::AdminDown);
  // The kernel also flags the socket (POLLERR); a receive consumes it and returns nothing.
  std::array<FrameBuffer, 2> out{};
  EXPECT_EQ(a->receive(out), 0U);

  // An invalid frame among them is counted once, as invalid, and the valid ones as unsent.
  const auto shorty = make_frame(6, 12);
  const std::array<FrameView, 3> mixed{FrameView(f), FrameView(shorty), FrameView(f)};
  const SendResult m = a->send(mixed);
  EXPECT_EQ(m.sent, 0U);
  EXPECT_EQ(m.invalid, 1U);
  EXPECT_EQ(m.unsent, 2U);
  EXPECT_EQ(a->counters().tx_invalid, 1U);
  EXPECT_EQ(a->counters().tx_down, 4U);

  veth_->set_up(VethPair::End::A, true);
  veth_->wait_up();
  ASSERT_TRUE(wait_state(*a, LinkState::Up, 2000ms)) << to_string(a->state());
  ASSERT_TRUE(wait_state(*b, LinkState::Up, 2000ms));
  EXPECT_EQ(a->send(FrameView(f)).sent, 1U);
  ASSERT_EQ(receive_frames(*b, 1, 2000ms).size(), 1U);
  // And the socket still receives after the interface's down and up.
  EXPECT_EQ(b->send(FrameView(f)).sent, 1U);
  ASSERT_EQ(receive_frames(*a, 1, 2000ms).size(), 1U);
  EXPECT_EQ(a->counters().link_downs, 1U);
  EXPECT_EQ(a->counters().link_ups, 1U);
}

TEST_F(RawSocketLinkTest, InterfaceThatDisappearsIsGoneAndIsBoundAgainWhenBack) {
  auto a = open_a();
  auto b = open_b();
  const int fd = a->wait_fd();
  veth_->remove();
  const auto f = make_frame(6);
  EXPECT_EQ(a->send(FrameView(f)).status, SendStatus::Down);
  EXPECT_EQ(a->poll_state(now()), LinkState::Gone);

  veth_->create();  // same names, new interface indexes
  ASSERT_TRUE(wait_state(*a, LinkState::Up, 2000ms)) << to_string(a->state());
  ASSERT_TRUE(wait_state(*b, LinkState::Up, 2000ms)) << to_string(b->state());
  EXPECT_EQ(a->wait_fd(), fd);  // the same socket, bound again
  EXPECT_EQ(a->send(FrameView(f)).sent, 1U);
  const auto got = receive_frames(*b, 1, 2000ms);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0], f);
  EXPECT_EQ(a->counters().link_ups, 1U);
}

TEST_F(RawSocketLinkTest, StateIsAskedOncePerIntervalOnly) {
  RawSocketOptions o;
  auto a = open_a();
  o.interface = veth_->a();
  o.state_interval = std::chrono::seconds(3600);
  RawSocketLink slow(o);
  {
    const NetnsScope in(*ns_a_);
    slow.open();
  }
  const core::TimePoint t = now();
  EXPECT_EQ(slow.poll_state(t), LinkState::Up);
  veth_->set_up(VethPair::End::B, false);
  ASSERT_TRUE(wait_state(*a, LinkState::NoCarrier, 2000ms));  // the kernel knows by now
  EXPECT_EQ(slow.poll_state(t + std::chrono::seconds(1)), LinkState::Up);  // not asked again yet
  EXPECT_EQ(slow.poll_state(t + std::chrono::seconds(3601)), LinkState::NoCarrier);
}

TEST_F(RawSocketLinkTest, CyclicCallsDoNotAllocate) {
  auto a = open_a();
  auto b = open_b();
  const auto f = make_frame(1, 200);
  const std::array<FrameView, 4> frames{FrameView(f), FrameView(f), FrameView(f), FrameView(f)};
  std::array<FrameBuffer, 8> out{};
  std::size_t received = 0;
  {
    const drivegate::test::AllocationScope scope;
    for (int cycle = 0; cycle < 50; ++cycle) {
      (void)a->send(frames);
      wait_readable(b->wait_fd(), 1000ms);
      received += b->receive(out);
      (void)a->poll_state(now());
      (void)b->counters();
    }
    EXPECT_EQ(scope.count(), 0U);
  }
  received += receive_frames(*b, 200 - received, 2000ms).size();
  EXPECT_EQ(received, 200U);
}

// open() errors: one line each, saying what is wrong and what to do.

TEST_F(RawSocketLinkTest, OpenNamesAMissingInterface) {
  const std::string e = open_error(*ns_a_, "dgtnosuch0");
  EXPECT_EQ(e, "ethercat: no network interface 'dgtnosuch0'; give the name of the Ethernet port the slaves are on");
}

TEST_F(RawSocketLinkTest, OpenSaysHowToBringADownInterfaceUp) {
  veth_->set_up(VethPair::End::A, false);
  const std::string e = open_error(*ns_a_, veth_->a());
  EXPECT_EQ(e, "ethercat: interface '" + veth_->a() + "' is down; bring it up with 'ip link set " + veth_->a() + " up'");
}

TEST_F(RawSocketLinkTest, OpenRefusesANonEthernetInterface) {
  const std::string e = open_error(*ns_a_, "lo");
  EXPECT_EQ(e, "ethercat: 'lo' is not an Ethernet interface (link type loopback); give the name of the Ethernet port the slaves are on");
}

TEST_F(RawSocketLinkTest, OpenRefusesNamesThatCannotBeInterfaces) {
  EXPECT_EQ(open_error(*ns_a_, ""), "ethercat: '' is not a network interface name (1 to 15 characters)");
  EXPECT_EQ(open_error(*ns_a_, "sixteen-chars-xx"),
            "ethercat: 'sixteen-chars-xx' is not a network interface name (1 to 15 characters)");
}

TEST_F(RawSocketLinkTest, OpenWithoutCapNetRawSaysHowToGrantIt) {
  const std::string iface = veth_->a();
  // A child inside namespace A drops CAP_NET_RAW (staying root, so only the capability differs)
  // and tries; it writes what open() said.
  ChildProcess child(ns_a_.get(), [&iface](int out) {
    __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
    std::array<__user_cap_data_struct, 2> data{};
    if (::syscall(SYS_capget, &header, data.data()) != 0) return 3;
    const unsigned bit = 1U << (CAP_NET_RAW % 32);
    data[CAP_NET_RAW / 32].effective &= ~bit;
    data[CAP_NET_RAW / 32].permitted &= ~bit;
    data[CAP_NET_RAW / 32].inheritable &= ~bit;
    if (::syscall(SYS_capset, &header, data.data()) != 0) return 4;
    RawSocketOptions o;
    o.interface = iface;
    RawSocketLink link(o);
    try {
      link.open();
      drivegate::test::write_line(out, "opened");
    } catch (const LinkError& e) {
      drivegate::test::write_line(out, e.what());
    }
    return 0;
  });
  const auto line = child.read_line(5000ms);
  ASSERT_TRUE(line.has_value());
  EXPECT_EQ(child.wait(5000ms), 0);
  std::array<char, 4096> self{};
  const ssize_t n = ::readlink("/proc/self/exe", self.data(), self.size() - 1);
  ASSERT_GT(n, 0);
  EXPECT_EQ(*line, "ethercat: no permission to open a raw Ethernet socket on '" + iface +
                       "' (CAP_NET_RAW missing); run as root or give the binary cap_net_raw, e.g. setcap cap_net_raw+ep " +
                       std::string(self.data(), static_cast<std::size_t>(n)));
}

TEST(RawSocketLinkClosed, SendsNothingAndSaysClosed) {
  RawSocketOptions o;
  o.interface = "eth0";
  RawSocketLink link(o);
  EXPECT_EQ(link.state(), LinkState::Closed);
  EXPECT_EQ(link.poll_state(now()), LinkState::Closed);
  EXPECT_EQ(link.wait_fd(), -1);
  const auto f = make_frame(1);
  const SendResult r = link.send(FrameView(f));
  EXPECT_EQ(r.status, SendStatus::Down);
  EXPECT_EQ(r.unsent, 1U);
  std::array<FrameBuffer, 1> out{};
  EXPECT_EQ(link.receive(out), 0U);
}

// The helpers themselves: everything they made is gone after their destructors.
TEST(Netns, EverythingIsRemovedAfterward) {
  if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
  std::string ns_name;
  std::string a_name;
  {
    NetNamespace ns;
    VethPair veth(&ns, nullptr);
    ns_name = ns.name();
    a_name = veth.a();
    EXPECT_LE(veth.a().size(), 15U);
    EXPECT_TRUE(ns.ip({"link", "show", veth.a()}).ok());
    EXPECT_TRUE(drivegate::test::run_ip({"link", "show", veth.b()}).ok());
  }
  EXPECT_NE(::access(("/run/netns/" + ns_name).c_str(), F_OK), 0);
  EXPECT_EQ(::if_nametoindex((a_name.substr(0, a_name.size() - 1) + "b").c_str()), 0U);
}

// What a crashed run left (its pid no longer alive) is removed; a live process's objects are not.
TEST(Netns, StaleObjectsOfDeadProcessesAreRemoved) {
  if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ASSERT_GT(dead, 0);
  ::waitpid(dead, nullptr, 0);
  const std::string stale_ns = std::string(drivegate::test::kNetnsPrefix) + std::to_string(dead) + "_0n";
  const std::string stale_if = std::string(drivegate::test::kNetnsPrefix) + std::to_string(dead) + "_1a";
  ASSERT_TRUE(drivegate::test::run_ip({"netns", "add", stale_ns}).ok());
  ASSERT_TRUE(drivegate::test::run_ip(
                  {"link", "add", stale_if, "type", "veth", "peer", "name", stale_if + "x"}).ok());
  NetNamespace mine;  // alive: must stay
  EXPECT_GE(drivegate::test::remove_stale_net_objects(), 2);
  EXPECT_NE(::access(("/run/netns/" + stale_ns).c_str(), F_OK), 0);
  EXPECT_EQ(::if_nametoindex(stale_if.c_str()), 0U);
  EXPECT_EQ(::access(("/run/netns/" + mine.name()).c_str(), F_OK), 0);
}

}  // namespace
}  // namespace drivegate::ethercat
