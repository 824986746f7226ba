#pragma once
// The controller's side of a veth pair for the tests of simulated devices on a real port: a
// RawSocketLink (frames), the RPC client and server UdpEndpoints on the interface's address, the
// DcpClient (with a StationFinder when one is set), and one AR (an ArPlan's CmClient and cyclic
// engines) once connect() starts it.
// poll() runs them all once; the cyclic engines start when the Connect is answered. Open it in
// the controller's namespace.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "adapters/link/raw_socket_link.hpp"
#include "adapters/link/udp_endpoint.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "adapters/profinet/wire/byte_order.hpp"
#include "tests/profinet_sim/sim_bench.hpp"

namespace drivegate::profinet::test {

class VethController {
 public:
  explicit VethController(const std::string& interface) {
    link::RawSocketOptions o;
    o.interface = interface;
    link_ = std::make_unique<link::RawSocketLink>(kFrameRules, o);
    rpc_client_ = std::make_unique<link::UdpEndpoint>(rpc_udp_options(interface));
    rpc_server_ = std::make_unique<link::UdpEndpoint>(rpc_udp_options(interface, kRpcUdpPort));
  }
  void open() {
    link_->open();
    rpc_client_->open();
    rpc_server_->open();
  }
  // Starts the AR of `plan` (which must outlive the controller).
  bool connect(ArPlan& plan, core::TimePoint now) {
    plan_ = &plan;
    cm_ = std::make_unique<CmClient>(plan.config);
    cyclic_ = false;
    return cm_->start(now, out_);
  }
  [[nodiscard]] std::vector<int> wait_fds() const {
    return {link_->wait_fd(), rpc_client_->wait_fd(), rpc_server_->wait_fd()};
  }

  // Sends what is due and takes what arrived.
  void poll(core::TimePoint now) {
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    while (const std::size_t n = finder ? finder->poll(now, buf) : dcp.poll(now, buf)) {
      (void)link_->send(std::span<const std::uint8_t>(buf).first(n));
    }
    std::array<link::FrameBuffer, 16> in{};
    while (const std::size_t n = link_->receive(in)) {
      for (std::size_t i = 0; i < n; ++i) {
        const auto f = std::span<const std::uint8_t>(in[i].bytes).first(in[i].size);
        (void)dcp.on_frame(f, now);
        if (plan_ != nullptr) (void)plan_->consumer->on_frame(f, now);
      }
    }
    if (!cm_) return;
    link::Datagram d;
    for (const auto& [port, socket] : {std::pair{rpc_client_.get(), CmSocket::Client}, std::pair{rpc_server_.get(), CmSocket::Server}}) {
      while (port->receive_from(d)) {
        cm_->on_datagram(d.view(), {get_be32(d.from.address, 0), d.from.port}, socket, now, out_);
      }
    }
    cm_->poll(now, out_);
    while (!out_.empty()) {
      const CmDatagram& g = out_.front();
      link::DatagramPort& port = g.from == CmSocket::Server ? *rpc_server_ : *rpc_client_;
      link::Ipv4Endpoint to{{}, g.to.port};
      put_be32(to.address, 0, g.to.ip);
      (void)port.send_to(to, g.view());
      out_.pop();
    }
    const CmClientState s = cm_->state();
    if (!cyclic_ && s != CmClientState::Connecting && s != CmClientState::Idle && s != CmClientState::Failed) {
      cyclic_ = true;
      for (std::size_t i = 0; i < plan_->provider->placements().size(); ++i) (void)plan_->provider->set_iops(i, iox_status::kGood);
      plan_->provider->start(now);
      plan_->consumer->arm(now);
    }
    while (const std::size_t n = plan_->provider->poll(now, buf)) {
      (void)link_->send(std::span<const std::uint8_t>(buf).first(n));
    }
    (void)plan_->consumer->poll(now);
  }

  [[nodiscard]] CmClient& cm() { return *cm_; }

  DcpClient dcp{kControllerMac};
  std::unique_ptr<StationFinder> finder;  // on `dcp`

 private:
  std::unique_ptr<link::RawSocketLink> link_;
  std::unique_ptr<link::UdpEndpoint> rpc_client_, rpc_server_;
  ArPlan* plan_ = nullptr;
  std::unique_ptr<CmClient> cm_;
  CmOutbox out_;
  bool cyclic_ = false;
};

}  // namespace drivegate::profinet::test
