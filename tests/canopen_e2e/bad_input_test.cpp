// Bad input on the bus while the axes run: a misbehaving peer in the test process (the gateway's
// own UdpMulticastTransport, and a plain UDP socket for datagrams no CAN frame encodes to) sends
// malformed and unexpected frames. The daemon counts and drops every one of them (the bus status'
// frames_dropped) and nothing else changes.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <vector>

#include "adapters/canopen/transport/msgpack_frame.hpp"
#include "adapters/canopen/transport/udp_multicast_transport.hpp"
#include "tests/canopen_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

using canopen::CanFrame;
using canopen::make_frame;
using client::AxisState;
using client::Outcome;

// A plain UDP socket sending arbitrary datagrams to the bus' group.
class DatagramSender {
 public:
  explicit DatagramSender(const BusAddress& bus) : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {
    in_addr lo{};
    ::inet_pton(AF_INET, "127.0.0.1", &lo);
    ::setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_IF, &lo, sizeof lo);
    to_.sin_family = AF_INET;
    to_.sin_port = htons(bus.port);
    ::inet_pton(AF_INET, bus.group.c_str(), &to_.sin_addr);
  }
  ~DatagramSender() { ::close(fd_); }
  DatagramSender(const DatagramSender&) = delete;
  DatagramSender& operator=(const DatagramSender&) = delete;

  bool send(const std::vector<std::uint8_t>& bytes) const {
    return ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_) ==
           static_cast<ssize_t>(bytes.size());
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

CanFrame extended(std::uint32_t id) {
  CanFrame f = make_frame(id, {0x01, 0x02});
  f.extended = true;
  return f;
}

CanFrame remote(std::uint32_t id) {
  CanFrame f = make_frame(id, {});
  f.remote = true;
  f.dlc = 8;
  return f;
}

// Frames the gateway must drop, none of which a drive could take for its own: the simulated drives
// see them too, and well-formed frames that impersonate a drive (a boot-up, a heartbeat with
// another state, an EMCY) would rightly change what the gateway does.
std::vector<CanFrame> bad_frames() {
  return {
      // SDO responses of the wrong length (SDO frames have 8 bytes, CiA 301 §7.2.4.3).
      make_frame(0x581, {0x43, 0x00, 0x10}),
      make_frame(0x583, {}),
      remote(0x582),
      // Unknown server command specifier (scs 7).
      make_frame(0x582, {0xE0, 0x00, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00}),
      // Responses nobody asked for: an upload of 1000h, a download confirmation of 6040h.
      make_frame(0x583, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}),
      make_frame(0x581, {0x60, 0x40, 0x60, 0x00, 0x00, 0x00, 0x00, 0x00}),
      // Node-IDs that are not configured: TPDO1, SDO response, heartbeat, EMCY.
      make_frame(0x18A, {0x37, 0x02, 0x01}),
      make_frame(0x58A, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}),
      make_frame(0x70A, {0x05}),
      make_frame(0x08A, {0x10, 0x43, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00}),
      // Configured nodes, wrong lengths: a heartbeat without its state, an EMCY without its error
      // register (3..7 bytes would be accepted: emcy_codec.hpp), a TPDO1 shorter than its map.
      make_frame(0x701, {}),
      make_frame(0x083, {0x10, 0x43}),
      make_frame(0x181, {0x37}),
      // A 29-bit frame: CANopen here is 11-bit only (AKD part 1 quirk 7).
      extended(0x18FF0001),
  };
}

// Datagrams that decode to no CAN frame: empty, not msgpack, a frame cut short, too long.
std::vector<std::vector<std::uint8_t>> garbage_datagrams() {
  std::vector<std::uint8_t> valid(canopen::kMsgpackFrameMaxSize);
  valid.resize(canopen::encode_msgpack_frame(make_frame(0x181, {0x37, 0x02}), 0, valid));
  return {
      {},
      {0xFF, 0x00, 0x13, 0x37},
      std::vector<std::uint8_t>(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2)),
      std::vector<std::uint8_t>(5000, 0x81),
  };
}

core::TimePoint now() { return core::SteadyClock{}.now(); }

class CanopenE2eBadInput : public CanopenE2eUp {
 protected:
  void SetUp() override {
    CanopenE2eUp::SetUp();
    if (HasFatalFailure()) return;
    for (const char* axis : {"akd", "sd6"}) {
      const auto r = send(axis, "enable");
      ASSERT_EQ(r.outcome, Outcome::Completed) << axis << ": " << r.reason << diagnostics();
    }
    ASSERT_TRUE(client_->wait_until([&] { return bus_status().has_value(); }, 5s));
  }

  // Waits until the bus status shows at least `more` frames dropped beyond `base`.
  bool dropped_rises(std::uint64_t base, std::uint64_t more) {
    return client_->wait_until([&] {
      const auto b = bus_status();
      return b && b->frames_dropped >= base + more;
    }, 5s);
  }

  // Nothing the peer sent changed the axes: links up, the enabled drives enabled, no fault.
  void expect_axes_unchanged() {
    for (const char* axis : {"akd", "nord", "sd6"}) {
      const auto s = state(axis);
      EXPECT_EQ(s.link, "operational") << axis;
      EXPECT_EQ(s.state, std::string(axis) == "nord" ? "switch_on_disabled" : "operation_enabled") << axis;
      EXPECT_EQ(s.fault_code, 0U) << axis;
    }
    for (const auto& e : events()) EXPECT_NE(e.kind, "fault") << e.axis << ": " << e.text;
  }
};

TEST_F(CanopenE2eBadInput, MalformedAndUnexpectedFramesAreCountedAndDropped) {
  canopen::UdpMulticastTransport peer(
      canopen::UdpMulticastOptions{.group = bus_.group, .port = bus_.port, .interface_address = "127.0.0.1"});
  peer.open();

  const auto frames = bad_frames();
  constexpr int kRounds = 5;
  const std::uint64_t before = bus_status()->frames_dropped;
  for (int round = 0; round < kRounds; ++round) {
    for (const auto& f : frames) ASSERT_EQ(peer.send(f, now()), canopen::SendResult::Sent) << std::hex << f.id;
  }
  EXPECT_TRUE(dropped_rises(before, kRounds * frames.size()))
      << "dropped " << bus_status()->frames_dropped - before << " of " << kRounds * frames.size() << diagnostics();
  EXPECT_TRUE(daemon_->running());
  expect_axes_unchanged();

  DatagramSender raw(bus_);
  const auto garbage = garbage_datagrams();
  const std::uint64_t before_garbage = bus_status()->frames_dropped;
  for (int round = 0; round < kRounds; ++round) {
    for (const auto& d : garbage) ASSERT_TRUE(raw.send(d)) << d.size() << " bytes";
  }
  EXPECT_TRUE(dropped_rises(before_garbage, kRounds * garbage.size()))
      << "dropped " << bus_status()->frames_dropped - before_garbage << " of " << kRounds * garbage.size()
      << diagnostics();
  EXPECT_TRUE(daemon_->running());
  expect_axes_unchanged();

  // The bus still works both ways: PDOs (a move), SDOs (a parameter read) and SYNC keep flowing.
  const auto received = bus_status()->frames_received;
  auto mv = request("akd", "move");
  mv.position = 5;
  const auto r = send(mv, 20s);
  EXPECT_EQ(r.outcome, Outcome::Completed) << r.reason << diagnostics();
  EXPECT_TRUE(wait_axis("akd", [](const AxisState& s) { return std::fabs(s.position - 5) < 0.001; }, 2s));
  client::ParamRequest a83;
  a83.axis = "sd6";
  a83.name = "A83";
  a83.type = "u8";
  const auto p = client_->param(a83, 5s);
  EXPECT_TRUE(p.ok && p.data == std::vector<std::uint8_t>{3}) << p.error;
  EXPECT_TRUE(client_->wait_until([&] { return bus_status()->frames_received > received + 100; }, 5s));
  std::string status;
  EXPECT_TRUE(sim_->wait_status([](const std::string& s) {
    for (int node : {1, 2, 3}) {
      const auto n = node_status(s, "can0", node);
      if (n.find("nmt=operational") == std::string::npos || n.find("fault=0x0000") == std::string::npos) return false;
    }
    return true;
  }, 1s, status)) << status;
  expect_axes_unchanged();
}

}  // namespace
}  // namespace drivegate::test
