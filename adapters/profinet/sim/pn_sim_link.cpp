#include "adapters/profinet/sim/pn_sim_link.hpp"

#include "adapters/profinet/wire/byte_order.hpp"

namespace drivegate::profinet {

namespace {

link::Ipv4Endpoint endpoint(std::uint32_t ip, std::uint16_t port) noexcept {
  link::Ipv4Endpoint e{{}, port};
  put_be32(e.address, 0, ip);
  return e;
}

UdpEndpoint endpoint(const link::Ipv4Endpoint& e) noexcept { return {get_be32(e.address, 0), e.port}; }

constexpr std::size_t kFramesPerReceive = 32;

}  // namespace

PnSimLinkRunner::PnSimLinkRunner(PnSimNetwork& network, link::Link& link, PortFactory ports)
    : network_(network), link_(link), make_port_(std::move(ports)), ports_(network.size()), frames_(kFramesPerReceive) {}

void PnSimLinkRunner::open() {
  link_.open();
  for (std::size_t i = 0; i < ports_.size(); ++i) {
    follow_address(i);
    if (!port_error_.empty()) throw link::LinkError(port_error_);
  }
}

void PnSimLinkRunner::follow_address(std::size_t device) {
  Ports& p = ports_[device];
  const std::uint32_t ip = network_.device(device).ip();
  if (ip == p.ip) return;  // also after a failure: tried once per address
  p = Ports{ip, nullptr, nullptr};
  if (ip == 0) return;
  try {
    auto server = make_port_(endpoint(ip, kRpcUdpPort));
    auto client = make_port_(endpoint(ip, kSimDeviceClientPort));
    server->open();
    client->open();
    p.server = std::move(server);
    p.client = std::move(client);
  } catch (const link::LinkError& e) {
    port_error_ = e.what();
  }
}

std::vector<int> PnSimLinkRunner::wait_fds() const {
  std::vector<int> fds{link_.wait_fd()};
  for (const Ports& p : ports_) {
    if (p.server) fds.push_back(p.server->wait_fd());
    if (p.client) fds.push_back(p.client->wait_fd());
  }
  return fds;
}

void PnSimLinkRunner::receive(link::DatagramPort& port, std::uint32_t ip, std::uint16_t port_number,
                              core::TimePoint now) noexcept {
  while (port.receive_from(datagram_)) {
    (void)network_.on_datagram(datagram_.view(), endpoint(datagram_.from), {ip, port_number}, now, *this);
  }
}

void PnSimLinkRunner::run_once(core::TimePoint now) {
  (void)link_.poll_state(now);
  while (const std::size_t n = link_.receive(frames_)) {
    for (std::size_t i = 0; i < n; ++i) network_.on_frame(std::span<const std::uint8_t>(frames_[i].bytes).first(frames_[i].size), now);
    if (n < frames_.size()) break;
  }
  for (const Ports& p : ports_) {
    if (!p.server) continue;
    receive(*p.server, p.ip, kRpcUdpPort, now);
    receive(*p.client, p.ip, kSimDeviceClientPort, now);
  }
  network_.poll(now, *this);
  // DCP may have given a device another address.
  for (std::size_t i = 0; i < ports_.size(); ++i) follow_address(i);
}

void PnSimLinkRunner::send_frame(std::span<const std::uint8_t> frame) noexcept { (void)link_.send(frame); }

void PnSimLinkRunner::send_datagram(const UdpEndpoint& from, const UdpEndpoint& to,
                                    std::span<const std::uint8_t> bytes) noexcept {
  for (const Ports& p : ports_) {
    if (p.ip != from.ip || !p.server) continue;
    link::DatagramPort& port = from.port == kRpcUdpPort ? *p.server : *p.client;
    (void)port.send_to(endpoint(to.ip, to.port), bytes);
    return;
  }
}

}  // namespace drivegate::profinet
