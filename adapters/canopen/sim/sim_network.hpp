#pragma once
// Simulated CANopen drives sharing one transport endpoint, as drives share one cable: every frame
// from the transport goes to every node, every frame a node sends goes to the transport and to
// the other nodes (a transport does not hand a sender's frames back to it). Any Transport works:
// the in-process bus (SimPeer below, for `transport: sim` buses) or udp-multicast (the
// drivegate-sim process, sim/tool/drivegate_sim_main.cpp).
//
// step() is the cyclic path: no allocation, lock, logging or blocking. Nodes are added before the
// first step.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/sim/slave_node.hpp"
#include "adapters/canopen/transport/inproc_bus.hpp"
#include "adapters/canopen/transport/transport.hpp"
#include "config/canopen/plan.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen::sim {

struct SimNetworkCounters {
  std::uint64_t received = 0;   // frames from the transport
  std::uint64_t unclaimed = 0;  // received frames no node took (other nodes' traffic, the master's heartbeat)
  std::uint64_t sent = 0;       // frames handed to the transport
  std::uint64_t send_failed = 0;  // the transport refused (busy, down, invalid); the frame is lost
};

class SimNetwork {
 public:
  // The transport stays the caller's and must be open while step() runs.
  explicit SimNetwork(Transport& transport);
  SimNetwork(const SimNetwork&) = delete;
  SimNetwork& operator=(const SimNetwork&) = delete;

  // Throws std::invalid_argument for a node-ID the network has already (and what SlaveNode throws).
  SlaveNode& add(SlaveNodeConfig config);

  // Receive everything waiting, hand it to the nodes, step each node and send what it produced.
  void step(core::TimePoint now) noexcept;

  [[nodiscard]] std::size_t size() const noexcept { return nodes_.size(); }
  [[nodiscard]] SlaveNode& node(std::size_t i) noexcept { return *nodes_[i]; }
  [[nodiscard]] SlaveNode* find(NodeId id) noexcept;
  [[nodiscard]] const SimNetworkCounters& counters() const noexcept { return counters_; }

 private:
  void deliver(const CanFrame& frame, const SlaveNode* sender, core::TimePoint now) noexcept;

  Transport& transport_;
  std::vector<std::unique_ptr<SlaveNode>> nodes_;
  std::array<CanFrame, 64> rx_{};
  TxQueue tx_;
  SimNetworkCounters counters_;
};

// The in-process wire's options for simulated drives of a plan's bus: each end may queue a whole
// cycle's frames at once (per node up to 4 PDOs, an SDO frame and error control, plus SYNC and NMT
// on the gateway side).
InprocBusOptions sim_wire_options(const config::BusPlan& plan);

// The simulated drives of a `transport: sim` canopen bus, stepped by the bus every cycle
// (CanopenBus calls step() before it receives). They sit on an in-process wire at the bus' bit
// rate (transport/inproc_bus.hpp); the gateway gets the other end of it.
class SimPeer final : public CyclePeer {
 public:
  struct Wiring {
    std::unique_ptr<Transport> gateway;  // for CanopenBus; keeps the wire alive as long as it lives
    std::unique_ptr<SimPeer> peer;
  };
  // One drive per axis: its device profile's persona and PDO maps, the drive model from
  // drive_config_for(). Throws std::invalid_argument (unknown persona, maps the persona refuses).
  static Wiring wire(const config::BusPlan& plan);

  ~SimPeer() override;
  void step(core::TimePoint now) noexcept override;

  [[nodiscard]] SimNetwork& network() noexcept { return network_; }
  [[nodiscard]] InprocBus& bus() noexcept { return *bus_; }
  // Fault injection: the gateway's CAN controller goes bus-off (or recovers).
  void set_gateway_bus_off(bool on) noexcept { bus_->set_bus_off(*gateway_end_, on); }

 private:
  explicit SimPeer(std::shared_ptr<InprocBus> bus);

  std::shared_ptr<InprocBus> bus_;  // shared with the gateway's end, which may outlive the peer
  std::unique_ptr<InprocEndpoint> endpoint_;
  const InprocEndpoint* gateway_end_ = nullptr;  // owned by the gateway's transport, which outlives the peer
  SimNetwork network_;
};

}  // namespace drivegate::canopen::sim
