#include "adapters/profinet/sim_transport.hpp"

#include <algorithm>

#include "adapters/link/memory_datagram_port.hpp"
#include "adapters/link/memory_link.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "adapters/profinet/sim/network_builder.hpp"
#include "adapters/profinet/wire/rpc.hpp"

namespace drivegate::profinet {

namespace {

// The shared state: the network, the controller's receive queues and the time of the last step.
class Hub final : public PnSimWire {
 public:
  Hub(PnSimNetwork& network, std::shared_ptr<void> keep, const SimControllerAddress& a)
      : network_(network),
        keep_(std::move(keep)),
        address_(a),
        frames_(kFrameRules, 512),
        client_(link::Ipv4Endpoint{ipv4_octets(a.ip), a.client_port}, 64),
        server_(link::Ipv4Endpoint{ipv4_octets(a.ip), kRpcUdpPort}, 64) {}

  void send_frame(std::span<const std::uint8_t> frame) noexcept override { (void)frames_.deliver(frame); }
  void send_datagram(const UdpEndpoint& from, const UdpEndpoint& to, std::span<const std::uint8_t> bytes) noexcept override {
    if (to.ip != address_.ip) return;
    if (to.port == kRpcUdpPort)
      (void)server_.deliver(link::Ipv4Endpoint{ipv4_octets(from.ip), from.port}, bytes);
    else if (to.port == address_.client_port)
      (void)client_.deliver(link::Ipv4Endpoint{ipv4_octets(from.ip), from.port}, bytes);
  }

  PnSimNetwork& network_;
  std::shared_ptr<void> keep_;
  SimControllerAddress address_;
  link::MemoryLink frames_;           // the controller's receive queue (frames_.deliver)
  link::MemoryDatagramPort client_;   // its receive queues
  link::MemoryDatagramPort server_;
  core::TimePoint now_{};
};

class HubLink final : public link::Link {
 public:
  explicit HubLink(std::shared_ptr<Hub> hub) : hub_(std::move(hub)) {}
  void open() override { hub_->frames_.open(); }
  void close() noexcept override { hub_->frames_.close(); }
  [[nodiscard]] bool is_open() const noexcept override { return hub_->frames_.is_open(); }
  link::SendResult send(std::span<const link::FrameView> frames) noexcept override {
    link::SendResult r;
    for (const link::FrameView f : frames) {
      if (!link::sendable(f, kFrameRules)) {
        ++r.invalid;
        continue;
      }
      hub_->network_.on_frame(f, hub_->now_);
      ++r.sent;
    }
    return r;
  }
  std::size_t receive(std::span<link::FrameBuffer> out) noexcept override { return hub_->frames_.receive(out); }
  [[nodiscard]] int wait_fd() const noexcept override { return -1; }
  link::LinkState poll_state(core::TimePoint now) noexcept override { return hub_->frames_.poll_state(now); }
  [[nodiscard]] link::LinkState state() const noexcept override { return hub_->frames_.state(); }
  [[nodiscard]] link::LinkCounters counters() const noexcept override { return hub_->frames_.counters(); }
  [[nodiscard]] std::string describe() const override { return "simulated PROFINET network"; }

 private:
  std::shared_ptr<Hub> hub_;
};

class HubPort final : public link::DatagramPort {
 public:
  HubPort(std::shared_ptr<Hub> hub, bool server) : hub_(std::move(hub)), queue_(server ? hub_->server_ : hub_->client_) {}
  void open() override { queue_.open(); }
  void close() noexcept override { queue_.close(); }
  [[nodiscard]] bool is_open() const noexcept override { return queue_.is_open(); }
  [[nodiscard]] link::Ipv4Endpoint local() const noexcept override { return queue_.local(); }
  link::DatagramStatus send_to(const link::Ipv4Endpoint& to, std::span<const std::uint8_t> payload) noexcept override {
    if (!queue_.is_open()) return link::DatagramStatus::Down;
    if (!link::sendable_datagram(payload)) return link::DatagramStatus::Invalid;
    const link::Ipv4Endpoint self = queue_.local();
    (void)hub_->network_.on_datagram(payload, UdpEndpoint{ipv4_host(self.address), self.port}, UdpEndpoint{ipv4_host(to.address), to.port},
                                     hub_->now_, *hub_);
    return link::DatagramStatus::Sent;
  }
  bool receive_from(link::Datagram& out) noexcept override { return queue_.receive_from(out); }
  [[nodiscard]] int wait_fd() const noexcept override { return -1; }
  [[nodiscard]] link::DatagramCounters counters() const noexcept override { return queue_.counters(); }
  [[nodiscard]] std::string describe() const override { return "simulated PROFINET network (udp)"; }

 private:
  std::shared_ptr<Hub> hub_;
  link::MemoryDatagramPort& queue_;
};

class HubPeer final : public PnCyclePeer {
 public:
  explicit HubPeer(std::shared_ptr<Hub> hub) : hub_(std::move(hub)) {}
  void step(core::TimePoint now) noexcept override {
    hub_->now_ = now;
    hub_->network_.poll(now, *hub_);
  }

 private:
  std::shared_ptr<Hub> hub_;
};

}  // namespace

ProfinetTransport sim_transport(PnSimNetwork& network, std::shared_ptr<void> keep, const SimControllerAddress& address) {
  auto hub = std::make_shared<Hub>(network, std::move(keep), address);
  ProfinetTransport t;
  t.frames = std::make_unique<HubLink>(hub);
  t.client = std::make_unique<HubPort>(hub, false);
  t.server = std::make_unique<HubPort>(hub, true);
  t.mac = address.mac;
  t.interface = "sim";
  t.peer = std::make_unique<HubPeer>(hub);
  return t;
}

}  // namespace drivegate::profinet

namespace drivegate::profinet {

std::unique_ptr<ProfinetBus> make_simulated_profinet_bus(const config::BusPlan& plan) {
  std::shared_ptr<BuiltPnNetwork> built;
  try {
    built = build_pn_network(plan, 0);  // one network per bus: its MACs need not differ from another bus'
  } catch (const PnBuildError& e) {
    throw core::BusError("bus '" + plan.name + "': " + e.what());
  }
  // The controller's address: the first host of the first station's subnet that no station has.
  const auto& o = plan.section<config::ProfinetBusOptions>();
  SimControllerAddress a;
  if (!o.stations.empty()) {
    const std::uint32_t net = o.stations.front().ip & o.stations.front().netmask;
    for (std::uint32_t host = net + 1; a.ip == 0 && host < net + 255; ++host)
      if (std::none_of(o.stations.begin(), o.stations.end(), [&](const config::ProfinetStation& s) { return s.ip == host; }))
        a.ip = host;
  }
  PnSimNetwork& network = built->network();
  return std::make_unique<ProfinetBus>(plan, sim_transport(network, std::move(built), a));
}

}  // namespace drivegate::profinet
