// UDP multicast transport: real sockets on loopback, each test on its own port so that tests (and
// other people's runs) proceed in parallel; and a live exchange with python-can inside a network
// namespace the test creates.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/canopen/transport/msgpack_frame.hpp"
#include "adapters/canopen/transport/udp_multicast_transport.hpp"
#include "tests/support/alloc_counter.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::canopen {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// Ports 20000..31999 (below the ephemeral range, where send sockets get theirs): a block of 12
// per process id, one per test.
std::uint16_t test_port(unsigned slot) {
  return static_cast<std::uint16_t>(20000 + (static_cast<unsigned>(::getpid()) % 1000) * 12 + slot);
}

UdpMulticastOptions options(std::uint16_t port) {
  UdpMulticastOptions o;
  o.port = port;
  return o;
}

core::TimePoint now() { return core::SteadyClock{}.now(); }

// Receives until `want` frames arrived or `done` says so, waiting on wait_fd() (never sleeping
// blind); gives up after five seconds.
template <typename Done>
std::vector<CanFrame> receive_until(Transport& t, Done done) {
  std::vector<CanFrame> got;
  std::array<CanFrame, 16> buf{};
  const auto deadline = Clock::now() + 5s;
  while (!done(got) && Clock::now() < deadline) {
    pollfd p{t.wait_fd(), POLLIN, 0};
    ::poll(&p, 1, 100);
    const auto n = t.receive(buf, now());
    got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  }
  return got;
}

std::vector<CanFrame> receive_n(Transport& t, std::size_t n) {
  return receive_until(t, [n](const std::vector<CanFrame>& got) { return got.size() >= n; });
}

CanFrame extended(std::uint32_t id, std::initializer_list<std::uint8_t> data) {
  CanFrame f = make_frame(id, data);
  f.extended = true;
  return f;
}

// A plain UDP socket that sends arbitrary datagrams to the group, as a misbehaving peer would.
class RawSender {
 public:
  explicit RawSender(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    in_addr lo{};
    ::inet_pton(AF_INET, "127.0.0.1", &lo);
    ::setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_IF, &lo, sizeof lo);
    to_.sin_family = AF_INET;
    to_.sin_port = htons(port);
    ::inet_pton(AF_INET, "239.74.163.2", &to_.sin_addr);
  }
  ~RawSender() { ::close(fd_); }
  RawSender(const RawSender&) = delete;
  RawSender& operator=(const RawSender&) = delete;
  void send(const std::vector<std::uint8_t>& bytes) const {
    ASSERT_EQ(::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_),
              static_cast<ssize_t>(bytes.size()));
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

std::vector<std::uint8_t> encoded(const CanFrame& f) {
  std::vector<std::uint8_t> b(kMsgpackFrameMaxSize);
  b.resize(encode_msgpack_frame(f, 0, b));
  return b;
}

// The datagram with the one-byte value after `key` replaced (keys are fixstr: A0h + length).
std::vector<std::uint8_t> with_value(std::vector<std::uint8_t> b, const std::string& key, std::uint8_t value) {
  std::vector<std::uint8_t> k{static_cast<std::uint8_t>(0xA0 | key.size())};
  k.insert(k.end(), key.begin(), key.end());
  const auto at = std::search(b.begin(), b.end(), k.begin(), k.end());
  EXPECT_NE(at, b.end()) << key;
  if (at != b.end()) *(at + static_cast<std::ptrdiff_t>(k.size())) = value;
  return b;
}

TEST(UdpMulticast, TwoTransportsExchangeFramesAndFilterTheirOwnEcho) {
  UdpMulticastTransport a(options(test_port(0)));
  UdpMulticastTransport b(options(test_port(0)));
  a.open();
  b.open();
  EXPECT_EQ(a.describe(), "udp-multicast 239.74.163.2:" + std::to_string(test_port(0)) + " on 127.0.0.1");
  CanFrame rtr;
  rtr.id = 0x705;
  rtr.remote = true;
  rtr.dlc = 1;
  ASSERT_EQ(a.send(make_frame(0x181, {1, 2, 3, 4, 5, 6, 7, 8}), now()), SendResult::Sent);
  ASSERT_EQ(a.send(extended(0x1ABCDE0, {0xDE, 0xAD}), now()), SendResult::Sent);
  ASSERT_EQ(a.send(rtr, now()), SendResult::Sent);
  const auto before = now();
  const auto got = receive_n(b, 3);
  ASSERT_EQ(got.size(), 3U);
  EXPECT_EQ(got[0].id, 0x181U);
  EXPECT_EQ(got[0].dlc, 8);
  EXPECT_EQ(got[0].data[7], 8);
  EXPECT_GE(got[0].timestamp, before);  // stamped with the receiver's time, not the sender's
  EXPECT_TRUE(got[1].extended);
  EXPECT_EQ(got[1].id, 0x1ABCDE0U);
  EXPECT_EQ(got[1].data[1], 0xAD);
  EXPECT_TRUE(got[2].remote);
  EXPECT_EQ(got[2].dlc, 1);

  // a saw its own three datagrams come back and dropped them.
  const auto echoes = receive_until(a, [&a](const auto&) { return a.counters().rx_filtered >= 3; });
  EXPECT_TRUE(echoes.empty());
  EXPECT_EQ(a.counters().rx_filtered, 3U);
  EXPECT_EQ(a.counters().tx_frames, 3U);
  EXPECT_EQ(b.counters().rx_frames, 3U);
  EXPECT_EQ(b.counters().rx_filtered, 0U);

  ASSERT_EQ(b.send(make_frame(0x581, {0x60}), now()), SendResult::Sent);
  const auto answer = receive_n(a, 1);
  ASSERT_EQ(answer.size(), 1U);
  EXPECT_EQ(answer[0].id, 0x581U);
  EXPECT_EQ(a.controller_state(), ControllerState::Active);
}

TEST(UdpMulticast, BadDatagramsAreCountedAndDropped) {
  UdpMulticastTransport t(options(test_port(1)));
  t.open();
  RawSender peer(test_port(1));
  auto truncated = encoded(make_frame(0x181, {1, 2}));
  truncated.resize(truncated.size() - 3);
  auto long_dlc = with_value(encoded(make_frame(0x181, {1, 2})), "dlc", 0x09);
  ASSERT_EQ(decode_msgpack_frame(long_dlc).error, MsgpackFrameError::DlcOutOfRange);
  auto fd = with_value(encoded(make_frame(0x181, {1})), "is_fd", 0xC3);
  ASSERT_EQ(decode_msgpack_frame(fd).error, MsgpackFrameError::CanFd);
  auto error_frame = with_value(encoded(make_frame(0x040, {0, 0, 0, 0, 0, 0, 0, 0})), "is_error_frame", 0xC3);
  ASSERT_TRUE(decode_msgpack_frame(error_frame).error_frame);

  peer.send({'h', 'e', 'l', 'l', 'o'});
  peer.send({});
  peer.send(truncated);
  peer.send(long_dlc);
  peer.send(fd);
  peer.send(std::vector<std::uint8_t>(5000, 0x80));  // longer than any frame, and than the buffer
  peer.send(error_frame);
  peer.send(encoded(make_frame(0x77F, {0x42})));  // the one good frame, last
  const auto got = receive_n(t, 1);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0].id, 0x77FU);
  const auto c = t.counters();
  EXPECT_EQ(c.rx_malformed, 6U);
  EXPECT_EQ(c.error_frames, 1U);
  EXPECT_EQ(c.rx_frames, 1U);
  EXPECT_EQ(t.controller_state(), ControllerState::Active);
}

// Mutated datagrams through the socket path: each is accounted for exactly once.
TEST(UdpMulticast, MutatedDatagramStreamIsFullyAccountedFor) {
  UdpMulticastTransport t(options(test_port(2)));
  t.open();
  RawSender peer(test_port(2));
  const auto seed = encoded(extended(0x18FF00AA, {1, 2, 3, 4, 5, 6, 7, 8}));
  std::uint32_t x = 12345;
  auto next = [&x] { return x = x * 1664525U + 1013904223U; };
  constexpr std::uint64_t kBatches = 20;
  constexpr std::uint64_t kPerBatch = 100;
  for (std::uint64_t batch = 0; batch < kBatches; ++batch) {
    for (std::uint64_t i = 0; i < kPerBatch; ++i) {
      auto d = seed;
      d[next() % d.size()] = static_cast<std::uint8_t>(next() >> 24);
      if (next() % 4 == 0) d.resize(next() % d.size());
      peer.send(d);
    }
    const auto expected = (batch + 1) * kPerBatch;
    receive_until(t, [&t, expected](const auto&) {
      const auto c = t.counters();
      return c.rx_frames + c.rx_malformed + c.error_frames + c.rx_filtered >= expected;
    });
  }
  const auto c = t.counters();
  EXPECT_EQ(c.rx_frames + c.rx_malformed + c.error_frames + c.rx_filtered, kBatches * kPerBatch);
  EXPECT_GT(c.rx_frames, 0U);
  EXPECT_GT(c.rx_malformed, 0U);
}

TEST(UdpMulticast, OpenErrorsAreOneClearLine) {
  auto open_error = [](UdpMulticastOptions o) -> std::string {
    UdpMulticastTransport t(std::move(o));
    try {
      t.open();
    } catch (const TransportError& e) {
      EXPECT_FALSE(t.is_open());
      return e.what();
    }
    return "";
  };
  auto o = options(test_port(3));
  o.group = "10.1.2.3";
  EXPECT_EQ(open_error(o), "udp-multicast: '10.1.2.3' is not an IPv4 multicast group address (224.0.0.0 to 239.255.255.255)");
  o.group = "239.74.163";
  EXPECT_NE(open_error(o).find("is not an IPv4 multicast group address"), std::string::npos);

  o = options(test_port(3));
  o.interface_address = "192.0.2.254";  // TEST-NET-1: on no interface of this machine
  std::string e = open_error(o);
  EXPECT_EQ(e.rfind("udp-multicast: no local interface has the address 192.0.2.254 (", 0), 0U) << e;
  EXPECT_NE(e.find("e.g. 127.0.0.1"), std::string::npos) << e;
  o.interface_address = "lo";
  EXPECT_NE(open_error(o).find("interface address 'lo' is not an IPv4 address"), std::string::npos);

  o = options(0);
  EXPECT_NE(open_error(o).find("port 0"), std::string::npos);
  o = options(test_port(3));
  o.ttl = 300;
  EXPECT_EQ(open_error(o), "udp-multicast: TTL 300 is not in 0..255");

  // A socket holding the port without sharing it.
  const int holder = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in any{};
  any.sin_family = AF_INET;
  any.sin_port = htons(test_port(4));
  ASSERT_EQ(::bind(holder, reinterpret_cast<const sockaddr*>(&any), sizeof any), 0);
  e = open_error(options(test_port(4)));
  ::close(holder);
  EXPECT_EQ(e, "udp-multicast: port " + std::to_string(test_port(4)) +
                   " is taken by a socket that does not share it (bind: Address already in use); stop that program or "
                   "choose another port");
  EXPECT_EQ(e.find('\n'), std::string::npos);
}

TEST(UdpMulticast, ClosedOrInvalidSendsAreRefused) {
  UdpMulticastTransport t(options(test_port(5)));
  EXPECT_EQ(t.send(make_frame(0x181, {}), now()), SendResult::Down);
  std::array<CanFrame, 2> buf{};
  EXPECT_EQ(t.receive(buf, now()), 0U);
  EXPECT_EQ(t.wait_fd(), -1);
  t.open();
  EXPECT_GE(t.wait_fd(), 0);
  t.open();  // already open: nothing changes
  EXPECT_EQ(t.send(make_frame(0x800, {}), now()), SendResult::Invalid);
  CanFrame too_long = make_frame(0x181, {});
  too_long.dlc = 9;
  EXPECT_EQ(t.send(too_long, now()), SendResult::Invalid);
  t.close();
  EXPECT_FALSE(t.is_open());
  EXPECT_EQ(t.send(make_frame(0x181, {}), now()), SendResult::Down);
}

// One send_batch() of more frames than one sendmmsg carries: every valid frame arrives at another
// member in order, the invalid one in the middle is refused (taken, not sent), nothing allocates;
// the sender drops its own echoes by their source and counts each, the other member still gets them.
TEST(UdpMulticast, BatchOfManyFramesArrivesInOrderAndEchoesAreDroppedAndCounted) {
  UdpMulticastTransport a(options(test_port(7)));
  UdpMulticastTransport b(options(test_port(7)));
  a.open();
  b.open();
  constexpr std::size_t kFrames = 2 * kUdpBatch + 22;
  std::vector<CanFrame> frames;
  for (std::size_t i = 0; i < kFrames; ++i)
    frames.push_back(make_frame(0x200 + static_cast<std::uint32_t>(i % 0x100), {static_cast<std::uint8_t>(i)}));
  frames[kUdpBatch + 3].dlc = 9;  // cannot exist on a bus
  SendBatchResult r;
  {
    test::AllocationScope scope;
    r = a.send_batch(frames, now());
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_FALSE(r.busy);
  EXPECT_EQ(r.taken, kFrames);
  EXPECT_EQ(r.sent, kFrames - 1);
  EXPECT_EQ(a.counters().tx_frames, kFrames - 1);
  EXPECT_EQ(a.counters().tx_overflows, 0U);

  const auto got = receive_n(b, kFrames - 1);
  ASSERT_EQ(got.size(), kFrames - 1);
  for (std::size_t i = 0, j = 0; i < kFrames; ++i) {
    if (i == kUdpBatch + 3) continue;
    EXPECT_EQ(got[j].id, frames[i].id) << i;
    EXPECT_EQ(got[j].data[0], frames[i].data[0]) << i;
    ++j;
  }
  // The sender reads its echoes only to drop them.
  std::array<CanFrame, 16> buf{};
  const auto deadline = Clock::now() + 5s;
  std::size_t own = 0;
  while (a.counters().rx_filtered < kFrames - 1 && Clock::now() < deadline) {
    pollfd p{a.wait_fd(), POLLIN, 0};
    ::poll(&p, 1, 100);
    own += a.receive(buf, now());
  }
  EXPECT_EQ(own, 0U);
  EXPECT_EQ(a.counters().rx_filtered, kFrames - 1);
  EXPECT_EQ(a.counters().rx_frames, 0U);
  EXPECT_EQ(b.counters().rx_frames, kFrames - 1);
  EXPECT_EQ(b.counters().rx_filtered, 0U);
}

// receive() reads no more datagrams than frames fit in its buffer: with more pending, the rest
// waits for the next call, in order, none lost.
TEST(UdpMulticast, ReceiveInBatchesNeverLosesWhatDoesNotFit) {
  UdpMulticastTransport a(options(test_port(8)));
  UdpMulticastTransport b(options(test_port(8)));
  a.open();
  b.open();
  std::vector<CanFrame> frames;
  for (std::uint8_t i = 0; i < 40; ++i) frames.push_back(make_frame(0x300, {i}));
  ASSERT_EQ(a.send_batch(frames, now()).sent, frames.size());
  std::vector<CanFrame> got;
  std::array<CanFrame, 7> buf{};
  const auto deadline = Clock::now() + 5s;
  while (got.size() < frames.size() && Clock::now() < deadline) {
    pollfd p{b.wait_fd(), POLLIN, 0};
    ::poll(&p, 1, 100);
    const auto n = b.receive(buf, now());
    ASSERT_LE(n, buf.size());
    got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  }
  ASSERT_EQ(got.size(), frames.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].data[0], i);
}

TEST(UdpMulticast, SendAndReceiveAllocateNothing) {
  UdpMulticastTransport a(options(test_port(6)));
  UdpMulticastTransport b(options(test_port(6)));
  a.open();
  b.open();
  std::array<CanFrame, 16> buf{};
  std::size_t sent = 0;
  std::size_t received = 0;
  const auto deadline = Clock::now() + 5s;
  test::AllocationScope scope;
  for (int i = 0; i < 50; ++i) {
    sent += a.send(make_frame(0x200, {static_cast<std::uint8_t>(i)}), core::TimePoint{}) == SendResult::Sent ? 1U : 0U;
  }
  while (received < sent && Clock::now() < deadline) {
    pollfd p{b.wait_fd(), POLLIN, 0};
    ::poll(&p, 1, 100);
    received += b.receive(buf, core::TimePoint{});
    a.receive(buf, core::TimePoint{});  // echoes
  }
  const auto allocations = scope.count();
  EXPECT_EQ(allocations, 0U);
  EXPECT_EQ(sent, 50U);
  EXPECT_EQ(received, 50U);
}

// --- live interop with python-can -------------------------------------------------------------

// A network namespace with only loopback up and the multicast range routed to it (nullptr, with
// the reason in `why`, when it cannot be made), deleted on every path out of the test.
std::unique_ptr<test::NetNamespace> multicast_netns(std::string& why) {
  try {
    auto ns = std::make_unique<test::NetNamespace>();
    const test::RunResult route = ns->ip({"route", "add", "224.0.0.0/4", "dev", "lo"});
    if (!route.ok()) {
      why = "ip route add 224.0.0.0/4 failed: " + route.output;
      return nullptr;
    }
    return ns;
  } catch (const std::exception& e) {
    why = e.what();
    return nullptr;
  }
}

// A program run in `ns` whose stdout and stderr we read line by line; killed and reaped if the
// test ends early.
class Child {
 public:
  Child(const test::NetNamespace& ns, std::vector<std::string> argv)
      : argv_(std::move(argv)), child_(&ns, [this](int out) {
          std::vector<char*> args;
          for (auto& a : argv_) args.push_back(a.data());
          args.push_back(nullptr);
          ::dup2(out, STDOUT_FILENO);
          ::dup2(out, STDERR_FILENO);
          ::execvp(args[0], args.data());
          return 127;
        }) {}

  // Reads output until a line equal to `line` came; false on timeout or when the child closes it.
  bool wait_for(const std::string& line, std::chrono::seconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      const std::optional<std::string> got = child_.read_line(left);
      if (!got) return false;
      output_ += *got + "\n";
      if (*got == line) return true;
    }
    return false;
  }
  // The exit status once it ends (within the timeout), else nullopt; then what it printed last.
  std::optional<int> exit_status(std::chrono::seconds timeout) {
    const std::optional<int> status = child_.wait(timeout);
    while (const std::optional<std::string> got = child_.read_line(1s)) output_ += *got + "\n";
    return status;
  }
  [[nodiscard]] const std::string& output() const { return output_; }

 private:
  std::vector<std::string> argv_;
  test::ChildProcess child_;
  std::string output_;
};

// The python-can peer: waits for our remote frame and data frame, checks them, and answers with
// an extended data frame (our data reversed) and a remote frame.
constexpr const char* kPythonPeer = R"(
import sys, can
bus = can.Bus(interface='udp_multicast', channel='239.74.163.2', port=int(sys.argv[1]))
print('ready', flush=True)
try:
    got = []
    while len(got) < 2:
        m = bus.recv(timeout=10)
        if m is None:
            print('timeout', flush=True)
            sys.exit(2)
        if m.arbitration_id in (0x18FF00AA, 0x181):
            got.append(m)
    rtr, data = got
    if not (rtr.is_remote_frame and rtr.is_extended_id and rtr.arbitration_id == 0x18FF00AA and rtr.dlc == 4):
        print('bad remote frame', rtr, flush=True)
        sys.exit(3)
    if (data.is_remote_frame or data.is_extended_id or data.is_error_frame or data.is_fd or data.dlc != 8
            or bytes(data.data) != bytes([0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88])):
        print('bad data frame', data, flush=True)
        sys.exit(3)
    bus.send(can.Message(arbitration_id=0x1ABCDE0, is_extended_id=True, data=bytes(reversed(data.data))))
    bus.send(can.Message(arbitration_id=0x705, is_extended_id=False, is_remote_frame=True, dlc=1))
    print('ok', flush=True)
finally:
    bus.shutdown()
)";

TEST(UdpMulticast, LiveInteropWithPythonCan) {
  if (!test::netns_unavailable().empty()) GTEST_SKIP() << test::netns_unavailable();
  // python-can joins the group on INADDR_ANY, i.e. on the interface of the default route; in a
  // namespace of our own that is loopback, so both peers meet there.
  std::string why;
  const auto ns = multicast_netns(why);
  if (!ns) GTEST_SKIP() << "ip netns failed: " << why;
  const std::uint16_t port = test_port(7);

  UdpMulticastTransport us(options(port));
  {
    test::NetnsScope inside(*ns);
    us.open();
  }
  Child peer(*ns, {"/usr/bin/python3", "-c", kPythonPeer, std::to_string(port)});
  ASSERT_TRUE(peer.wait_for("ready", 20s)) << peer.output();

  CanFrame rtr;
  rtr.id = 0x18FF00AA;
  rtr.extended = true;
  rtr.remote = true;
  rtr.dlc = 4;
  ASSERT_EQ(us.send(rtr, now()), SendResult::Sent);
  ASSERT_EQ(us.send(make_frame(0x181, {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88}), now()), SendResult::Sent);

  const auto got = receive_n(us, 2);
  const auto status = peer.exit_status(20s);  // also collects what the peer printed
  EXPECT_EQ(status, std::optional<int>(0)) << peer.output();
  ASSERT_EQ(got.size(), 2U) << peer.output();
  EXPECT_EQ(got[0].id, 0x1ABCDE0U);
  EXPECT_TRUE(got[0].extended);
  EXPECT_FALSE(got[0].remote);
  ASSERT_EQ(got[0].dlc, 8);
  EXPECT_EQ(got[0].data[0], 0x88);
  EXPECT_EQ(got[0].data[7], 0x11);
  EXPECT_EQ(got[1].id, 0x705U);
  EXPECT_TRUE(got[1].remote);
  EXPECT_EQ(got[1].dlc, 1);
  EXPECT_NE(peer.output().find("ok\n"), std::string::npos) << peer.output();
  EXPECT_EQ(us.counters().rx_malformed, 0U);
  EXPECT_EQ(us.counters().rx_filtered, 2U);  // our two frames came back to us
}

TEST(UdpMulticast, WithInterfaceAnyOwnEchoesAreDroppedWhileAPeerReceivesThem) {
  if (!test::netns_unavailable().empty()) GTEST_SKIP() << test::netns_unavailable();
  // With interface 0.0.0.0 (the configuration default) the send socket is bound to 0.0.0.0 and
  // the kernel sends from an address of the interface the group's route leads to. In a namespace
  // of our own that is loopback, given a global address (127.0.0.1 is host scope, never chosen
  // as a multicast source) as a NIC has one. Nothing leaves this host.
  std::string why;
  const auto ns = multicast_netns(why);
  if (!ns) GTEST_SKIP() << "ip netns failed: " << why;
  const test::RunResult address = ns->ip({"addr", "add", "198.51.100.7/32", "dev", "lo"});
  if (!address.ok()) GTEST_SKIP() << "ip netns failed: cannot set up " << ns->name() << ": " << address.output;
  auto o = options(test_port(9));
  o.interface_address = "0.0.0.0";
  UdpMulticastTransport us(o);
  UdpMulticastTransport peer(o);
  {
    test::NetnsScope inside(*ns);
    us.open();
    peer.open();
  }
  ASSERT_EQ(us.send(make_frame(0x80, {}), now()), SendResult::Sent);  // a SYNC
  ASSERT_EQ(us.send(make_frame(0x000, {0x01, 0x00}), now()), SendResult::Sent);

  const auto at_peer = receive_n(peer, 2);
  ASSERT_EQ(at_peer.size(), 2U);
  EXPECT_EQ(at_peer[0].id, 0x80U);
  EXPECT_EQ(at_peer[1].id, 0x000U);
  const auto echoes = receive_until(us, [&us](const auto&) { return us.counters().rx_filtered >= 2; });
  EXPECT_TRUE(echoes.empty()) << "own frame decoded as a peer's, id " << std::hex << echoes.front().id;
  EXPECT_EQ(us.counters().rx_filtered, 2U);
  EXPECT_EQ(us.counters().rx_frames, 0U);
  EXPECT_EQ(peer.counters().rx_filtered, 0U);
}

}  // namespace
}  // namespace drivegate::canopen
