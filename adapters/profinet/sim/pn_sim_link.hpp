#pragma once
// A PnSimNetwork on real ports: its frames over a link::Link (a RawSocketLink with
// profinet::kFrameRules on the simulator's end of a veth pair or an Ethernet port), its RPC
// datagrams over two link::DatagramPorts per device, the server port 34964 and the client port
// kSimDeviceClientPort (its ApplicationReady calls), on the device's IP address
// (link::UdpEndpoint with UdpOptions::address; the address must be on the interface).
//
// A device without an address has no ports; when DCP gives it one (or another), run_once() opens
// its ports on the new address, and a failure to do so is kept in port_error(), one line.
// Opening allocates; run_once() does not otherwise.
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "adapters/link/datagram.hpp"
#include "adapters/link/link.hpp"
#include "adapters/profinet/sim/pn_sim_network.hpp"

namespace drivegate::profinet {

class PnSimLinkRunner final : private PnSimWire {
 public:
  // Makes (does not open) the datagram port for one device address and port.
  using PortFactory = std::function<std::unique_ptr<link::DatagramPort>(const link::Ipv4Endpoint& local)>;

  PnSimLinkRunner(PnSimNetwork& network, link::Link& link, PortFactory ports);

  // Opens the link and the ports of every device with an address; throws link::LinkError.
  void open();
  // Takes everything that arrived, runs the devices, sends what they send.
  void run_once(core::TimePoint now);
  // When run_once() has work without anything arriving.
  [[nodiscard]] core::TimePoint next_deadline() const noexcept { return network_.next_deadline(); }
  // The file descriptors that become readable when something arrives (link and open ports).
  [[nodiscard]] std::vector<int> wait_fds() const;
  // The last failure to open a device's ports ("" when none).
  [[nodiscard]] const std::string& port_error() const noexcept { return port_error_; }

 private:
  struct Ports {
    std::uint32_t ip = 0;  // the device address they were made for (open when server is set)
    std::unique_ptr<link::DatagramPort> server;
    std::unique_ptr<link::DatagramPort> client;
  };

  void send_frame(std::span<const std::uint8_t> frame) noexcept override;
  void send_datagram(const UdpEndpoint& from, const UdpEndpoint& to, std::span<const std::uint8_t> bytes) noexcept override;
  // Opens (or moves) the device's ports to its current address.
  void follow_address(std::size_t device);
  void receive(link::DatagramPort& port, std::uint32_t ip, std::uint16_t port_number, core::TimePoint now) noexcept;

  PnSimNetwork& network_;
  link::Link& link_;
  PortFactory make_port_;
  std::vector<Ports> ports_;
  std::vector<link::FrameBuffer> frames_;
  link::Datagram datagram_{};
  std::string port_error_;
};

}  // namespace drivegate::profinet
