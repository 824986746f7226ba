// UdpEndpoint over a veth pair with addresses the test assigns: a controller (ephemeral port) and a
// device (port 34964) exchange datagrams with their sources; open() fails with one line for each
// thing a person has to fix; drops are counted.
#include <linux/capability.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <vector>

#include "adapters/link/udp_endpoint.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "adapters/profinet/wire/rpc.hpp"
#include "tests/profinet_link/veth.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet {
namespace {

using drivegate::test::ChildProcess;
using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using link::DatagramStatus;
using link::Ipv4Endpoint;
using link::UdpEndpoint;
using namespace std::chrono_literals;

constexpr Ipv4Endpoint kDeviceAddress{{10, 77, 0, 2}, kRpcUdpPort};

class ProfinetUdpTest : public test::VethTest {
 protected:
  void SetUp() override {
    VethTest::SetUp();
    if (IsSkipped()) return;
    const auto a = ns_a_->ip({"addr", "add", "10.77.0.1/24", "dev", veth_->a()});
    ASSERT_TRUE(a.ok()) << a.output;
    const auto b = ns_b_->ip({"addr", "add", "10.77.0.2/24", "dev", veth_->b()});
    ASSERT_TRUE(b.ok()) << b.output;
  }

  static std::unique_ptr<UdpEndpoint> open_in(const NetNamespace& ns, link::UdpOptions o) {
    auto e = std::make_unique<UdpEndpoint>(std::move(o));
    const NetnsScope in(ns);
    e->open();
    return e;
  }
  static std::string open_error(const NetNamespace& ns, const link::UdpOptions& o) {
    UdpEndpoint e(o);
    const NetnsScope in(ns);
    try {
      e.open();
    } catch (const link::LinkError& err) {
      return err.what();
    }
    return "";
  }
  // Receives one datagram, waiting up to 2 s.
  static bool receive(link::DatagramPort& p, link::Datagram& out) {
    for (const auto end = std::chrono::steady_clock::now() + 2s; std::chrono::steady_clock::now() < end;) {
      if (p.receive_from(out)) return true;
      test::wait_readable(p.wait_fd(), 50ms);
    }
    return false;
  }
};

TEST_F(ProfinetUdpTest, ControllerAndDeviceExchangeDatagramsWithTheirSources) {
  auto device = open_in(*ns_b_, rpc_udp_options(veth_->b(), kRpcUdpPort));
  auto controller = open_in(*ns_a_, rpc_udp_options(veth_->a()));
  EXPECT_EQ(device->local(), kDeviceAddress);
  const Ipv4Endpoint mine = controller->local();
  EXPECT_EQ(mine.address, (std::array<std::uint8_t, 4>{10, 77, 0, 1}));
  EXPECT_NE(mine.port, 0);
  EXPECT_EQ(controller->describe(), "udp " + veth_->a() + " " + link::to_string(mine));

  const std::vector<std::uint8_t> request{0x04, 0x00, 0x20, 0x00, 0x10};
  link::Datagram in;
  {
    const drivegate::test::AllocationScope scope;
    EXPECT_EQ(controller->send_to(kDeviceAddress, request), DatagramStatus::Sent);
    ASSERT_TRUE(receive(*device, in));
    EXPECT_EQ(device->send_to(in.from, in.view()), DatagramStatus::Sent);  // the answer goes to the source
    EXPECT_EQ(scope.count(), 0U);
  }
  EXPECT_EQ(in.from, mine);
  EXPECT_EQ(std::vector<std::uint8_t>(in.view().begin(), in.view().end()), request);
  ASSERT_TRUE(receive(*controller, in));
  EXPECT_EQ(in.from, kDeviceAddress);
  EXPECT_EQ(controller->counters().rx_datagrams, 1U);
  EXPECT_EQ(controller->send_to(kDeviceAddress, {}), DatagramStatus::Invalid);
}

TEST_F(ProfinetUdpTest, SecondAddressOfTheInterfaceIsBoundWhenAsked) {
  ASSERT_TRUE(ns_b_->ip({"addr", "add", "10.77.0.3/24", "dev", veth_->b()}).ok());
  link::UdpOptions o = rpc_udp_options(veth_->b(), kRpcUdpPort);
  o.address = {10, 77, 0, 3};
  auto second = open_in(*ns_b_, o);
  auto first = open_in(*ns_b_, rpc_udp_options(veth_->b(), kRpcUdpPort));  // the same port on the primary
  EXPECT_EQ(second->local(), (Ipv4Endpoint{{10, 77, 0, 3}, kRpcUdpPort}));
  auto controller = open_in(*ns_a_, rpc_udp_options(veth_->a()));
  const std::vector<std::uint8_t> hello{1, 2, 3};
  EXPECT_EQ(controller->send_to(second->local(), hello), DatagramStatus::Sent);
  link::Datagram in;
  ASSERT_TRUE(receive(*second, in));
  EXPECT_EQ(in.from, controller->local());
  EXPECT_FALSE(first->receive_from(in));
  o.address = {10, 77, 0, 9};
  EXPECT_EQ(open_error(*ns_b_, o), "profinet: address 10.77.0.9 is not on interface '" + veth_->b() +
                                       "'; add it, e.g. 'ip addr add 10.77.0.9/24 dev " + veth_->b() + "'");
}

TEST_F(ProfinetUdpTest, OpenSaysWhatIsWrongInOneLine) {
  EXPECT_EQ(open_error(*ns_a_, rpc_udp_options("dgtnosuch0")),
            "profinet: no network interface 'dgtnosuch0'; give the name of the Ethernet port the devices are on");
  EXPECT_EQ(open_error(*ns_a_, rpc_udp_options("")), "profinet: '' is not a network interface name (1 to 15 characters)");
  {
    auto holder = open_in(*ns_b_, rpc_udp_options(veth_->b(), kRpcUdpPort));
    EXPECT_EQ(open_error(*ns_b_, rpc_udp_options(veth_->b(), kRpcUdpPort)),
              "profinet: UDP port 34964 on 10.77.0.2 (interface '" + veth_->b() +
                  "') is in use by another socket; stop the program that holds it (see 'ss -ulpn sport = :34964') "
                  "or choose another port");
  }
  veth_->set_up(drivegate::test::VethPair::End::A, false);
  EXPECT_EQ(open_error(*ns_a_, rpc_udp_options(veth_->a())),
            "profinet: interface '" + veth_->a() + "' is down; bring it up with 'ip link set " + veth_->a() + " up'");
  veth_->set_up(drivegate::test::VethPair::End::A, true);
  ASSERT_TRUE(ns_a_->ip({"addr", "flush", "dev", veth_->a()}).ok());
  EXPECT_EQ(open_error(*ns_a_, rpc_udp_options(veth_->a())),
            "profinet: interface '" + veth_->a() + "' has no IPv4 address; give it one, e.g. 'ip addr add "
            "192.168.0.1/24 dev " + veth_->a() + "' (an address in the devices' subnet)");
}

TEST_F(ProfinetUdpTest, PortBelow1024WithoutCapNetBindServiceSaysHowToGrantIt) {
  const std::string iface = veth_->a();
  // A child inside namespace A drops CAP_NET_BIND_SERVICE (staying root, so only the capability
  // differs) and tries port 1000; it writes what open() said.
  ChildProcess child(ns_a_.get(), [&iface](int out) {
    __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
    std::array<__user_cap_data_struct, 2> data{};
    if (::syscall(SYS_capget, &header, data.data()) != 0) return 3;
    const unsigned bit = 1U << (CAP_NET_BIND_SERVICE % 32);
    data[CAP_NET_BIND_SERVICE / 32].effective &= ~bit;
    data[CAP_NET_BIND_SERVICE / 32].permitted &= ~bit;
    if (::syscall(SYS_capset, &header, data.data()) != 0) return 4;
    UdpEndpoint e(rpc_udp_options(iface, 1000));
    try {
      e.open();
      drivegate::test::write_line(out, "opened");
    } catch (const link::LinkError& err) {
      drivegate::test::write_line(out, err.what());
    }
    return 0;
  });
  const auto line = child.read_line(5000ms);
  ASSERT_TRUE(line.has_value());
  EXPECT_EQ(line->rfind("profinet: no permission to bind UDP port 1000 on 10.77.0.1 (interface '" + iface +
                            "'): ports below 1024 need CAP_NET_BIND_SERVICE; run as root, choose a port from 1024 on, "
                            "or give the binary cap_net_bind_service, e.g. setcap cap_net_bind_service+ep /",
                        0),
            0U)
      << *line;
}

TEST_F(ProfinetUdpTest, CountsTooLongDatagramsAndKernelDrops) {
  link::UdpOptions o = rpc_udp_options(veth_->b(), kRpcUdpPort);
  o.receive_buffer_bytes = 4096;  // the kernel doubles it; a few datagrams fill it
  auto device = open_in(*ns_b_, o);
  // A plain UDP socket in namespace A sends what UdpEndpoint itself would refuse (too long).
  const NetnsScope in_a(*ns_a_);
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(kRpcUdpPort);
  std::memcpy(&to.sin_addr, kDeviceAddress.address.data(), 4);
  const auto send = [&](std::size_t size) {
    const std::vector<std::uint8_t> payload(size, 0xA5);
    return ::sendto(fd, payload.data(), payload.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) ==
           static_cast<ssize_t>(size);
  };
  ASSERT_TRUE(send(link::kMaxDatagramBytes + 1));
  ASSERT_TRUE(send(8));
  link::Datagram d;
  ASSERT_TRUE(receive(*device, d));
  EXPECT_EQ(d.size, 8U);
  EXPECT_EQ(device->counters().rx_too_long, 1U);

  // 100 datagrams into a buffer that holds a few: the kernel drops the rest and reports the count
  // with the next datagram it queues. Markers follow, read one by one, until every datagram sent is
  // accounted for (received or dropped).
  std::uint64_t sent = 0;
  for (int i = 0; i < 100; ++i) sent += send(1000) ? 1U : 0U;
  const auto end = std::chrono::steady_clock::now() + 5s;
  for (;;) {
    while (device->receive_from(d)) {
    }
    const link::DatagramCounters c = device->counters();
    if (c.rx_datagrams - 1 + c.rx_overflow == sent || std::chrono::steady_clock::now() > end) break;
    sent += send(8) ? 1U : 0U;
    test::wait_readable(device->wait_fd(), 50ms);
  }
  ::close(fd);
  const link::DatagramCounters c = device->counters();
  EXPECT_GT(c.rx_overflow, 0U);
  EXPECT_EQ(c.rx_datagrams - 1 + c.rx_overflow, sent);
}

}  // namespace
}  // namespace drivegate::profinet
